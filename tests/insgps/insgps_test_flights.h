#pragma once
// Simulated flights shared by the insgps tests (sim/gps_flight.h), built from YAML text so
// that they read like the config/ins_gps files.

#include <gtest/gtest.h>

#include <string>

#include "cvslam/insgps/insgps_run.h"
#include "cvslam/io/config_node.h"
#include "cvslam/sim/gps_flight.h"

namespace cvslam::insgps::test {

/// A figure of eight with 35° tilts (config/ins_gps/sharp_manoeuvres.yaml, 40 s by default).
inline std::string sharpFlightYaml(uint64_t seed, double duration_s = 40.0) {
  return "seed: " + std::to_string(seed) + "\nduration_s: " + std::to_string(duration_s) + R"(
trajectory: {kind: figure8, centre: [0.0, 0.0], half_length: 60.0, half_width: 50.0,
             altitude: 30.0, period: 30.0, tilt: quadrotor, max_tilt_deg: 35.0}
imu: {rate_hz: 200.0, noise: true, gyro_random_walk: 0.0, accel_random_walk: 0.0}
gps: {rate_hz: 5.0, sigma_horizontal: 1.5, sigma_vertical: 3.0, sigma_velocity: 0.1}
)";
}

/// A smooth 90 s loop at 10 m/s with no fixes in [30, 50) s.
inline std::string outageFlightYaml(uint64_t seed) {
  return "seed: " + std::to_string(seed) + R"(
duration_s: 90.0
trajectory: {kind: loop, centre: [0.0, 0.0], semi_axes: [150.0, 100.0], altitude: 40.0,
             altitude_amplitude: 5.0, speed: 10.0, tilt: bank}
imu: {rate_hz: 200.0, noise: true, gyro_random_walk: 0.0, accel_random_walk: 0.0}
gps: {rate_hz: 5.0, sigma_horizontal: 1.5, sigma_vertical: 3.0, sigma_velocity: 0.1,
      outages: [{start_s: 30.0, end_s: 50.0}]}
)";
}

inline FlightData simulate(const std::string& yaml) {
  auto cfg = ConfigNode::fromString(yaml, "test flight");
  EXPECT_TRUE(cfg.ok());
  sim::GpsFlightOptions o;
  const Status st = o.load(*cfg);
  EXPECT_TRUE(st.ok()) << st.message();
  auto flight = sim::simulateGpsFlight(o);
  EXPECT_TRUE(flight.ok()) << flight.status().message();
  return FlightData{flight->imu, flight->gps, flight->truth};
}

}  // namespace cvslam::insgps::test
