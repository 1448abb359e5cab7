// ImuNoiseMonitor (ins/imu_noise_monitor.h): the white-noise density of an IMU measured from its
// own samples, whatever the motion, and the INS model taking the larger of it and its datasheet.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvslam/ins/imu_noise_monitor.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/io/config_node.h"

namespace cvslam {
namespace {

constexpr double kRateHz = 200.0;
constexpr double kGyroDensity = 1.6968e-4;  // the ADIS16448 datasheet's
constexpr double kAccelDensity = 2.0e-3;

/// A manoeuvring vehicle's IMU at 200 Hz from t0 to t1: smooth motion (rates of ±1 rad/s and
/// ±3 m/s² swinging at 0.5 Hz) plus white noise of `scale` × the datasheet's densities and a
/// rotor line of the given amplitudes at 117 Hz (aliased at 200 Hz, as euroc_recorded_mh.yaml).
void fly(double t0, double t1, double scale, double vib_accel, double vib_gyro, std::mt19937& rng,
         ImuNoiseMonitor* monitor) {
  const double dt = 1.0 / kRateHz;
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sg = scale * kGyroDensity / std::sqrt(dt),
               sa = scale * kAccelDensity / std::sqrt(dt);
  for (double t = t0; t < t1; t += dt) {
    ImuSample s;
    s.t_us = static_cast<int64_t>(std::llround(t * 1e6));
    const double swing = std::sin(2.0 * M_PI * 0.5 * t), rotor = std::sin(2.0 * M_PI * 117.0 * t);
    for (int i = 0; i < 3; ++i) {
      s.gyro_B(i) = swing * (1.0 + 0.2 * i) + sg * n01(rng) + vib_gyro * rotor;
      s.accel_B(i) = 3.0 * swing + (i == 2 ? -9.81 : 0.0) + sa * n01(rng) + vib_accel * rotor;
    }
    monitor->add(s);
  }
}

TEST(ImuNoiseMonitor, MeasuresTheWhiteNoiseDensityWhileTheVehicleManoeuvres) {
  for (const double scale : {1.0, 20.0}) {
    std::mt19937 rng(7);
    ImuNoiseMonitor monitor;
    fly(0.0, 10.0, scale, 0.0, 0.0, rng, &monitor);
    ASSERT_TRUE(monitor.ready());
    // 4 s of 25 ms blocks: 160 overlapping third differences × 3 axes, a median: ±7 % (1σ).
    EXPECT_NEAR(monitor.gyroDensity() / (scale * kGyroDensity), 1.0, 0.2) << scale;
    EXPECT_NEAR(monitor.accelDensity() / (scale * kAccelDensity), 1.0, 0.2) << scale;
  }
}

TEST(ImuNoiseMonitor, TheSimulatedRotorLineIsNotCountedAsNoise) {
  // The recorded scenarios' 117 Hz line of 0.5 m/s² and 0.02 rad/s integrates to under 1 mm/s
  // between two frames; per sample it is 19× the accelerometer's density, over 25 ms blocks
  // (where it aliases to a whole number of cycles) it is gone.
  std::mt19937 rng(8);
  ImuNoiseMonitor monitor;
  fly(0.0, 10.0, 1.0, 0.5, 0.02, rng, &monitor);
  EXPECT_LT(monitor.accelDensity(), 1.3 * kAccelDensity);
  EXPECT_LT(monitor.gyroDensity(), 1.3 * kGyroDensity);
  ImuNoiseMonitorOptions per_sample;
  per_sample.tau_s = 1.0 / kRateHz;  // one sample a block: the line counts in full
  ImuNoiseMonitor naive(per_sample);
  fly(0.0, 10.0, 1.0, 0.5, 0.02, rng, &naive);
  EXPECT_GT(naive.accelDensity(), 10.0 * kAccelDensity);
  // Disabled (a simulated IMU's filter, whose densities are true): never ready.
  ImuNoiseMonitorOptions off;
  off.enabled = false;
  ImuNoiseMonitor disabled(off);
  fly(0.0, 10.0, 1.0, 0.5, 0.02, rng, &disabled);
  EXPECT_FALSE(disabled.ready());
  EXPECT_EQ(disabled.accelDensity(), 0.0);
}

TEST(ImuNoiseMonitor, FollowsTakeOffOverItsWindowAndNeedsEnoughTerms) {
  std::mt19937 rng(9);
  ImuNoiseMonitor monitor;
  fly(0.0, 0.4, 1.0, 0.0, 0.0, rng, &monitor);  // 15 blocks closed: a dozen third differences
  EXPECT_FALSE(monitor.ready());
  EXPECT_EQ(monitor.accelDensity(), 0.0);
  fly(0.4, 10.0, 1.0, 0.0, 0.0, rng, &monitor);  // the datasheet's noise
  EXPECT_NEAR(monitor.accelDensity() / kAccelDensity, 1.0, 0.2);
  // The median holds the ground's noise until the flight fills half the window, then follows.
  fly(10.0, 11.0, 30.0, 0.0, 0.0, rng, &monitor);  // a quarter of the window
  EXPECT_LT(monitor.accelDensity(), 2.0 * kAccelDensity);
  fly(11.0, 13.0, 30.0, 0.0, 0.0, rng, &monitor);  // three quarters
  EXPECT_GT(monitor.accelDensity(), 15.0 * kAccelDensity);
  fly(13.0, 20.0, 30.0, 0.0, 0.0, rng, &monitor);  // the window holds the flight only
  EXPECT_NEAR(monitor.accelDensity() / (30.0 * kAccelDensity), 1.0, 0.2);
  // A sample not later than the last is ignored.
  ImuSample old;
  old.t_us = 0;
  old.accel_B.setConstant(1e6);
  const double before = monitor.accelDensity();
  monitor.add(old);
  fly(20.0, 20.1, 30.0, 0.0, 0.0, rng, &monitor);
  EXPECT_NEAR(monitor.accelDensity(), before, 0.05 * before);
}

TEST(ImuNoiseMonitor, TheInsModelAssumesTheLargerOfMeasuredAndConfigured) {
  InsPropagatorOptions o;
  o.estimate_imu_bias = true;
  o.noise_density_scale = 2.0;
  InsPropagator ins(o);
  const double dt = 0.005;
  const Eigen::VectorXd configured = ins.noiseVariances(dt);
  // Below the scaled datasheet: bit for bit the configured model.
  ins.setMeasuredNoiseDensities(1.5 * o.gyro_noise_density, 1.5 * o.accel_noise_density);
  EXPECT_EQ(ins.noiseVariances(dt), configured);
  EXPECT_DOUBLE_EQ(ins.gyroNoiseDensity(), 2.0 * o.gyro_noise_density);
  // Above it: the measured white noises, the random walks unchanged.
  ins.setMeasuredNoiseDensities(0.004, 0.06);
  const Eigen::VectorXd measured = ins.noiseVariances(dt);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(measured(i), 0.06 * 0.06 / dt, 1e-12) << i;
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(measured(i), 0.004 * 0.004 / dt, 1e-15) << i;
  EXPECT_EQ(measured.tail<6>(), configured.tail<6>());
  EXPECT_DOUBLE_EQ(ins.accelNoiseDensity(), 0.06);
}

TEST(ImuNoiseMonitor, OptionsLoadPrintAndValidate) {
  auto cfg = ConfigNode::fromString(
      "{measure_noise_density: false, noise_tau_s: 0.05, noise_window_s: 2.0}", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  InsPropagatorOptions o;
  ASSERT_TRUE(o.load(*cfg).ok());
  EXPECT_FALSE(o.noise_monitor.enabled);
  EXPECT_DOUBLE_EQ(o.noise_monitor.tau_s, 0.05);
  auto printed = ConfigNode::fromString(o.print(), "printed");
  ASSERT_TRUE(printed.ok());
  InsPropagatorOptions back;
  ASSERT_TRUE(back.load(*printed).ok());
  EXPECT_EQ(back.print(), o.print());
  auto bad_tau = ConfigNode::fromString("{noise_tau_s: 0}", "t.yaml");
  EXPECT_EQ(InsPropagatorOptions().load(*bad_tau).message(), "t.yaml: noise_tau_s: must be > 0");
  auto bad_window = ConfigNode::fromString("{noise_tau_s: 0.1, noise_window_s: 0.3}", "t.yaml");
  EXPECT_EQ(InsPropagatorOptions().load(*bad_window).message(),
            "t.yaml: noise_window_s: must be at least 4 × noise_tau_s");
}

}  // namespace
}  // namespace cvslam
