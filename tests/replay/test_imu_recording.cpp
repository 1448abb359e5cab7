// ImuRecording and ImuOptions::recording: a real IMU stream replaces the synthesised one,
// rotated into the body, interpolated, aligned with the TUM trajectory's clock.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <utility>
#include <vector>

#include "cvslam/ins/imu_noise_monitor.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/scenario/imu_recording.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario_setup/scenario_calibration.h"
#include "cvslam/sim/simulator.h"
#include "euroc_test_folder.h"
#include "test_paths.h"

namespace cvslam::sim {
namespace {

TEST(ImuRecording, RotatesAndInterpolates) {
  test::TempFolder tmp;
  std::ofstream(tmp / "imu.csv") << "#timestamp [ns],wx,wy,wz,ax,ay,az\n"
                                    "1000000000,0.1,0.2,0.3,9.8,0.0,1.0\n"
                                    "1010000000,0.3,0.2,0.1,9.6,0.0,3.0\n";
  Eigen::Matrix3d R_StoB;
  R_StoB << 0, 0, 1, 0, 1, 0, -1, 0, 0;  // EuRoC S (x up, z forward) → FRD
  auto r = ImuRecording::load(tmp / "imu.csv", R_StoB);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_DOUBLE_EQ((*r)->startTime(), 1.0);
  EXPECT_DOUBLE_EQ((*r)->endTime(), 1.01);
  const ImuSample a = (*r)->sampleAt(1.0, 42);
  EXPECT_EQ(a.t_us, 42);
  EXPECT_LT((a.accel_B - Eigen::Vector3d(1.0, 0.0, -9.8)).norm(), 1e-12);  // up = −z_B
  EXPECT_LT((a.gyro_B - Eigen::Vector3d(0.3, 0.2, -0.1)).norm(), 1e-12);
  const ImuSample mid = (*r)->sampleAt(1.005, 0);
  EXPECT_LT((mid.accel_B - Eigen::Vector3d(2.0, 0.0, -9.7)).norm(), 1e-9);
}

TEST(ImuRecording, ErrorsNameTheFile) {
  test::TempFolder tmp;
  std::ofstream(tmp / "short.csv") << "#t,wx,wy,wz,ax,ay,az\n1,0,0,0,0,0,0\n";
  auto r = ImuRecording::load(tmp / "short.csv", Eigen::Matrix3d::Identity());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("short.csv"), std::string::npos);
  auto missing = ImuRecording::load(tmp / "nope.csv", Eigen::Matrix3d::Identity());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("nope.csv"), std::string::npos);
}

/// The first 2 s of euroc_mh03_hall, whose UAV 3 plays the real MH_03 IMU recording.
Expected<Simulator> hallSimulator() {
  auto scenario = Scenario::loadFile(test::sourceDir() + "/config/scenarios/euroc_mh03_hall.yaml");
  if (!scenario.ok()) return scenario.status();
  scenario->duration = 2.0;
  return Simulator::create(*scenario);
}

TEST(ImuRecording, EurocHallScenarioPlaysTheRealMh03Imu) {
  auto sim = hallSimulator();
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  Eigen::Matrix3d R_StoB;
  R_StoB << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  auto rec = ImuRecording::load(test::sharedDataDir() + "/euroc/imu/MH_03_medium_imu0.csv", R_StoB);
  ASSERT_TRUE(rec.ok());
  const double tum_start = 1403637132.88832;  // first line of MH_03_medium.tum
  AgentSimulator& uav3 = sim->agent(2);
  ASSERT_EQ(uav3.id(), 3);
  SimEvent e;
  int n = 0;
  double mean_norm = 0.0, mean_up = 0.0;
  while (uav3.next(e)) {
    if (e.type != SensorEventType::kImu) continue;
    const ImuSample want = (*rec)->sampleAt(tum_start + 1e-6 * static_cast<double>(e.t_us), e.t_us);
    EXPECT_LT((e.imu.accel_B - want.accel_B).norm(), 1e-9) << e.t_us;
    EXPECT_LT((e.imu.gyro_B - want.gyro_B).norm(), 1e-9) << e.t_us;
    mean_norm += e.imu.accel_B.norm();
    mean_up += -e.imu.accel_B.z();  // FRD: "up" is −z (S's x axis points up)
    ++n;
  }
  EXPECT_EQ(n, 401);
  // Slow flight at the start of MH_03: the specific force is about g.
  EXPECT_NEAR(mean_norm / n, 9.81, 0.5);
  EXPECT_GT(mean_up / n, 8.5);  // a mostly level body: the remap to FRD is right
  // Synthesised UAV 1 is not the recording.
  SimEvent e1;
  ASSERT_TRUE(sim->agent(0).next(e1));
  EXPECT_EQ(e1.type, SensorEventType::kImu);
}

TEST(ImuRecording, KnownPoseStartMeasuresTheTurnOnGyroBiasAtRest) {
  // MH_03's IMU records 2.4 s before the ground truth starts, the first 2 s at rest: the known
  // pose of the start says nothing of the real turn-on bias (0.077 rad/s about the sensor's x,
  // 77σ of the configured prior), so it is measured there, as before a take-off.
  auto sim = hallSimulator();
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  const std::vector<ImuSample> before = sim->agent(2).imuBeforeStart();
  ASSERT_GT(before.size(), 400u);
  EXPECT_LT(before.back().t_us, 0);
  EXPECT_GT(before.back().t_us, -10'000);               // up to the last sample before the flight
  EXPECT_TRUE(sim->agent(0).imuBeforeStart().empty());  // synthesised: nothing before 0

  VisualInertialSlamOptions options;
  options.ins.estimate_imu_bias = true;
  const AgentFilterSetup uav3 = simulatedAgentSetup(sim->agent(2).scenarioAgent(), options);
  const Eigen::Vector3d bias = uav3.x0.segment<3>(vehicle::kGyroBias);
  // The recording's mean rate over its first second, rotated S → body (x_B = z_S, z_B = −x_S).
  double sum_x = 0.0;
  int n = 0;
  for (const ImuSample& s : before) {
    if (s.t_us - before.front().t_us >= 1'000'000) break;
    sum_x += s.gyro_B.x();
    ++n;
  }
  EXPECT_NEAR(bias.x(), sum_x / n, 2e-4);  // the same window, up to its edge sample
  EXPECT_NEAR(bias.x(), 0.077, 0.003);
  EXPECT_LT(bias.tail<2>().norm(), 0.03);
  const double sigma = std::sqrt(uav3.P0(vehicle::kGyroBias, vehicle::kGyroBias));
  EXPECT_GE(sigma, options.slam.initial_gyro_bias_sigma);
  EXPECT_LT(sigma, 0.01);
  // A synthesised IMU's filter starts at a draw from the configured prior σ around the IMU's
  // true turn-on bias (perturb_biases, the default), not at a bias measured at rest.
  const AgentFilterSetup uav1 = simulatedAgentSetup(sim->agent(0).scenarioAgent(), options);
  const Eigen::Vector3d drawn =
      uav1.x0.segment<3>(vehicle::kGyroBias) - sim->agent(0).initialEstimate().state.gyro_bias;
  EXPECT_FALSE(drawn.isZero());
  EXPECT_LT(drawn.cwiseAbs().maxCoeff(), 5.0 * options.slam.initial_gyro_bias_sigma);
  // The synthesised IMU's filter has its true densities, the recording's the datasheet's with
  // the datasheet factor on the random walks.
  EXPECT_DOUBLE_EQ(uav1.options.ins.datasheet_random_walk_scale, 1.0);
  EXPECT_DOUBLE_EQ(uav3.options.ins.datasheet_random_walk_scale,
                   options.ins.datasheet_random_walk_scale);
  EXPECT_GT(options.ins.datasheet_random_walk_scale, 1.0);
  // The recording's filter measures its white noise in flight; the synthesised one's is true.
  EXPECT_FALSE(uav1.options.ins.noise_monitor.enabled);
  EXPECT_TRUE(uav3.options.ins.noise_monitor.enabled);
  // Nobody drew the recording's turn-on accelerometer bias from the prior: it starts with the
  // recorded IMU's σ, the synthesised IMU's filter with the configured one.
  const double ba3 = std::sqrt(uav3.P0(vehicle::kAccelBias, vehicle::kAccelBias));
  const double ba1 = std::sqrt(uav1.P0(vehicle::kAccelBias, vehicle::kAccelBias));
  EXPECT_DOUBLE_EQ(ba3, options.slam.recorded_accel_bias_sigma);
  EXPECT_DOUBLE_EQ(ba1, options.slam.initial_accel_bias_sigma);
  EXPECT_GT(options.slam.recorded_accel_bias_sigma, options.slam.initial_accel_bias_sigma);
}

TEST(ImuRecording, TheRealImuInFlightIsTensOfTimesNoisierThanItsDatasheet) {
  // MH_03's ADIS16448 on the hexacopter, in flight: about 30× its datasheet's white noise over
  // 25 ms blocks (rotor vibration; docs/results/euroc_recorded.md "In-flight noise"). This is
  // what the filter of a recording assumes (ins.measure_noise_density).
  Eigen::Matrix3d R_StoB;
  R_StoB << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  auto recording =
      ImuRecording::load(test::sharedDataDir() + "/euroc/imu/MH_03_medium_imu0.csv", R_StoB);
  ASSERT_TRUE(recording.ok()) << recording.status().message();
  const auto measure = [&](double from_s, double to_s) {
    ImuNoiseMonitor monitor;
    for (double t = from_s; t < to_s; t += 0.005) {
      monitor.add((*recording)
                      ->sampleAt((*recording)->startTime() + t,
                                 static_cast<int64_t>(std::llround(t * 1e6))));
    }
    EXPECT_TRUE(monitor.ready());
    return std::make_pair(monitor.gyroDensity(), monitor.accelDensity());
  };
  const InsPropagatorOptions datasheet;
  const auto [gyro_flight, accel_flight] = measure(40.0, 44.0);
  EXPECT_GT(gyro_flight, 10.0 * datasheet.gyro_noise_density);
  EXPECT_LT(gyro_flight, 60.0 * datasheet.gyro_noise_density);
  EXPECT_GT(accel_flight, 10.0 * datasheet.accel_noise_density);
  EXPECT_LT(accel_flight, 60.0 * datasheet.accel_noise_density);
}

TEST(ImuRecording, RecordingMustCoverTheRun) {
  auto scenario = Scenario::loadFile(test::sourceDir() + "/config/scenarios/euroc_mh03_hall.yaml");
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  scenario->agents[2].imu.recording_start = 1403637264.0;  // 1.5 s before the file ends
  auto sim = Simulator::create(*scenario);
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.status().message().find("does not cover"), std::string::npos)
      << sim.status().message();
}

}  // namespace
}  // namespace cvslam::sim
