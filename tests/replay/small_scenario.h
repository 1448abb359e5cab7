#pragma once
// A small, short scenario for the replay tests: two UAVs circling 10 m above the aerial
// world, 320×240 cameras at 10 Hz, 200 Hz IMU; noise-free on request.
#include <fstream>
#include <string>

namespace cvslam::test {

inline std::string smallScenarioYaml(double duration, bool imu_noise) {
  const std::string noise = imu_noise ? "true" : "false";
  return "name: replay_test\nseed: 11\nduration: " + std::to_string(duration) +
         "\nworld: {landmark_density: 0.3, margin: 20.0}\n"
         "agents:\n"
         "  - id: 1\n"
         "    trajectory: {kind: circle, centre: [0, 0], radius: 15, altitude: 10, speed: 3,"
         " tilt: quadrotor}\n"
         "    imu: {rate_hz: 200, noise: " +
         noise +
         "}\n"
         "    camera_rate_hz: 10\n"
         "  - id: 2\n"
         "    trajectory: {kind: figure8, centre: [0, 0], half_length: 20, half_width: 16,"
         " altitude: 12, period: 30, tilt: quadrotor}\n"
         "    imu: {rate_hz: 200, noise: " +
         noise +
         "}\n"
         "    camera_rate_hz: 10\n";
}

/// Writes the scenario to `path` and returns the path.
inline std::string writeSmallScenario(const std::string& path, double duration, bool imu_noise) {
  std::ofstream(path) << smallScenarioYaml(duration, imu_noise);
  return path;
}

}  // namespace cvslam::test
