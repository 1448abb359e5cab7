#include "cvslam/ins/static_initializer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "cvslam/core/random.h"
#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/slam/agent_setup.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "test_paths.h"

namespace cvslam {
namespace {

constexpr double kG = 9.81;
constexpr double kAccelBiasSigma = 0.1;  // [m/s²]

/// IMU at rest with attitude `euler`, gyro bias `bg`, accel bias `ba`, white noise.
std::vector<ImuSample> restingImu(const Eigen::Vector3d& euler, const Eigen::Vector3d& bg,
                                  const Eigen::Vector3d& ba, double seconds, double accel_sigma,
                                  double gyro_sigma, uint64_t seed) {
  Rng rng(seed);
  const Eigen::Vector3d f_B = -rotationNavToBody<double>(euler) * Eigen::Vector3d(0, 0, kG);
  std::vector<ImuSample> out;
  for (int k = 0; k <= static_cast<int>(seconds * 200); ++k) {
    ImuSample s;
    s.t_us = 1403715273262142 + k * 5000;  // EuRoC-epoch time, 200 Hz
    for (int i = 0; i < 3; ++i) {
      s.accel_B(i) = f_B(i) + ba(i) + accel_sigma * rng.gaussian();
      s.gyro_B(i) = bg(i) + gyro_sigma * rng.gaussian();
    }
    out.push_back(s);
  }
  return out;
}

TEST(StaticInitializer, RecoversTiltAndGyroBiasAtRest) {
  const Eigen::Vector3d euler(0.3, -0.2, 1.1), bg(0.08, -0.01, 0.02);
  const auto imu = restingImu(euler, bg, Eigen::Vector3d::Zero(), 2.0, 0.02, 0.002, 7);
  StaticInitializerOptions o;
  auto init = initializeAtRest(imu, o, kG, kAccelBiasSigma);
  ASSERT_TRUE(init.ok()) << init.status().message();
  EXPECT_NEAR(init->euler(0), euler(0), 1e-3);
  EXPECT_NEAR(init->euler(1), euler(1), 1e-3);
  EXPECT_EQ(init->euler(2), 0.0);  // yaw defines the estimator's frame
  EXPECT_LT((init->gyro_bias - bg).norm(), 5e-4);
  EXPECT_EQ(init->samples, 201);  // the first window_s = 1 s at 200 Hz, both ends included
  EXPECT_EQ(init->t_us, imu[200].t_us);
  EXPECT_NEAR(init->gyro_bias_sigma(0), 0.002 / std::sqrt(201.0), 3e-5);
  EXPECT_NEAR(init->tilt_sigma, kAccelBiasSigma / kG, 1e-12);
  // The down direction is right whatever the attitude: also at pitch 90° (the EuRoC IMU's
  // mounting), where the Euler roll is undefined.
  const auto upright = restingImu(Eigen::Vector3d(0.0, M_PI / 2, 0.0), bg, Eigen::Vector3d::Zero(),
                                  1.0, 0.0, 0.0, 1);
  auto init90 = initializeAtRest(upright, o, kG, kAccelBiasSigma);
  ASSERT_TRUE(init90.ok());
  const Eigen::Vector3d down_B =
      rotationBodyToNav<double>(init90->euler).transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT((down_B - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-9);
}

// Rotors shake a standing MAV's IMU (EuRoC: up to 1.1 m/s², 0.08 rad/s RMS) by more than a
// slow motion would: rest is the stability of the mean, so the vibration does not matter.
/// The EuRoC VI-sensor's IMU mounting (x axis up, pitch 90°): the rest state is a rotation
/// with gravity along N's z (Euler angles are singular there), and the error-state filter
/// started from it (restSetup, VisualInertialSlam) stays where it stands.
TEST(StaticInitializer, StartsAnErrorStateFilterWithTheImuXAxisUp) {
  const Eigen::Vector3d euler(0.4, M_PI / 2, -0.7), bg(0.05, -0.01, 0.02);
  const auto imu = restingImu(euler, bg, Eigen::Vector3d::Zero(), 4.0, 0.02, 0.002, 11);
  auto init = initializeAtRest(imu, StaticInitializerOptions{}, kG, kAccelBiasSigma);
  ASSERT_TRUE(init.ok()) << init.status().message();
  const Eigen::Vector3d down_B = rotationNavToBody<double>(euler).col(2);
  const Eigen::Matrix3d R_NtoB = init->q_BtoN.toRotationMatrix().transpose();
  EXPECT_LT((R_NtoB.col(2) - down_B).norm(), 1e-3);
  // FRD-level attitudes keep yaw zero: the rotation is that of the Euler angles.
  const auto level =
      restingImu(Eigen::Vector3d(0.1, -0.2, 0.0), bg, Eigen::Vector3d::Zero(), 2.0, 0.0, 0.0, 3);
  auto level_init = initializeAtRest(level, StaticInitializerOptions{}, kG, kAccelBiasSigma);
  ASSERT_TRUE(level_init.ok());
  EXPECT_LT((level_init->q_BtoN.toRotationMatrix() - rotationBodyToNav(level_init->euler)).norm(),
            1e-9);

  VisualInertialSlamOptions options;
  options.ins.attitude = vehicle::Attitude::kErrorState;
  options.ins.estimate_imu_bias = true;
  const AgentFilterSetup setup = restSetup(*init, InitialUncertainty{}, options);
  ASSERT_TRUE(setup.q0_BtoN.has_value());
  VisualInertialSlam slam(options, StereoCamera{});
  ASSERT_TRUE(slam.initialize(setup.t0_us, setup.x0, *setup.q0_BtoN, setup.P0).ok());
  for (const ImuSample& s : imu) {
    if (s.t_us > setup.t0_us) {
      ASSERT_TRUE(slam.addImu(s).ok());
    }
  }
  ASSERT_TRUE(slam.propagateTo(imu.back().t_us).ok());
  EXPECT_LT(slam.vehiclePose().p_BinN.norm(), 0.01);  // 3 s standing, x axis up
  EXPECT_TRUE(slam.vehicleCovariance().allFinite());
  // The Euler filter cannot start there: its initial state sits on the singularity.
  options.ins.attitude = vehicle::Attitude::kEuler;
  VisualInertialSlam euler_slam(options, StereoCamera{});
  EXPECT_FALSE(euler_slam.initialize(setup.t0_us, setup.x0, *setup.q0_BtoN, setup.P0).ok());
}

TEST(StaticInitializer, RotorVibrationIsStillRest) {
  const Eigen::Vector3d euler(-0.1, 0.05, 0.0), bg(0.0, 0.02, -0.07);
  auto imu = restingImu(euler, bg, Eigen::Vector3d::Zero(), 1.0, 0.05, 0.003, 11);
  for (std::size_t k = 0; k < imu.size(); ++k) {
    const double phase = 2.0 * M_PI * 93.0 * static_cast<double>(k) * 0.005;  // 93 Hz rotor
    imu[k].accel_B += Eigen::Vector3d(0.4, 1.5, 0.2) * std::sin(phase);
    imu[k].gyro_B += Eigen::Vector3d(0.1, 0.02, 0.03) * std::cos(phase);
  }
  auto init = initializeAtRest(imu, StaticInitializerOptions{}, kG, kAccelBiasSigma);
  ASSERT_TRUE(init.ok()) << init.status().message();
  EXPECT_GT(init->accel_std.maxCoeff(), 1.0);
  EXPECT_NEAR(init->euler(0), euler(0), 2e-3);
  EXPECT_NEAR(init->euler(1), euler(1), 2e-3);
  EXPECT_LT((init->gyro_bias - bg).norm(), 2e-3);
}

// An accelerometer bias cannot be told from a tilt at rest: the tilt error it causes stays
// within the stated 1σ bound for a bias of that size.
TEST(StaticInitializer, AccelBiasShowsAsTiltWithinItsSigma) {
  StaticInitializerOptions o;
  const Eigen::Vector3d ba(kAccelBiasSigma, 0.0, 0.0);
  const auto imu = restingImu(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), ba, 1.0, 0, 0, 3);
  auto init = initializeAtRest(imu, o, kG, kAccelBiasSigma);
  ASSERT_TRUE(init.ok());
  EXPECT_GT(std::abs(init->euler(1)), 0.5 * init->tilt_sigma);
  EXPECT_LT(std::abs(init->euler(1)), 1.01 * init->tilt_sigma);
}

TEST(StaticInitializer, RefusesWithOneClearLine) {
  StaticInitializerOptions o;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  auto short_rest =
      initializeAtRest(restingImu(zero, zero, zero, 0.5, 0, 0, 1), o, kG, kAccelBiasSigma);
  ASSERT_FALSE(short_rest.ok());
  EXPECT_NE(short_rest.status().message().find("rest period too short: 0.500 s"), std::string::npos)
      << short_rest.status().message();

  // Starts to accelerate forward (1 m/s²) or to turn (0.1 rad/s) half-way through.
  auto accelerating = restingImu(zero, zero, zero, 1.0, 0.0, 0.0, 2);
  for (std::size_t k = 100; k < accelerating.size(); ++k) accelerating[k].accel_B.x() += 1.0;
  auto moving = initializeAtRest(accelerating, o, kG, kAccelBiasSigma);
  ASSERT_FALSE(moving.ok());
  EXPECT_NE(moving.status().message().find("not at rest"), std::string::npos);
  EXPECT_NE(moving.status().message().find("mean specific force changes by 0.50"),
            std::string::npos)
      << moving.status().message();

  auto turning = restingImu(zero, zero, zero, 1.0, 0.0, 0.0, 2);
  for (std::size_t k = 100; k < turning.size(); ++k) turning[k].gyro_B.z() += 0.1;
  auto turned = initializeAtRest(turning, o, kG, kAccelBiasSigma);
  ASSERT_FALSE(turned.ok());
  EXPECT_NE(turned.status().message().find("mean angular rate changes"), std::string::npos);

  auto milli_g = restingImu(zero, zero, zero, 1.0, 0.0, 0.0, 2);
  for (auto& s : milli_g) s.accel_B /= kG;  // specific force in g, not m/s²
  auto units = initializeAtRest(milli_g, o, kG, kAccelBiasSigma);
  ASSERT_FALSE(units.ok());
  EXPECT_NE(units.status().message().find("wrong units"), std::string::npos);

  EXPECT_FALSE(initializeAtRest({}, o, kG, kAccelBiasSigma).ok());
  auto bad = restingImu(zero, zero, zero, 1.0, 0.0, 0.0, 2);
  bad[10].gyro_B.x() = std::nan("");
  EXPECT_FALSE(initializeAtRest(bad, o, kG, kAccelBiasSigma).ok());
}

// Real data: the first second of EuRoC V1_01's ADIS16448 (the MAV stands on the floor; IMU
// mounted x up, pitch ≈ 90° in FRD terms). The down direction agrees with the ground truth
// within the accelerometer-bias bound, the gyro bias with the ground truth's estimate.
TEST(StaticInitializer, RealEurocImuAtRest) {
  auto d = EurocDataset::open(test::sharedDataDir() + "/euroc_micro");
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_TRUE(d->hasGroundTruth());
  StaticInitializerOptions o;
  auto init = initializeAtRest(d->imu(), o, kG, kAccelBiasSigma);
  ASSERT_TRUE(init.ok()) << init.status().message();
  const EurocGroundTruth& gt = d->groundTruth().front();
  // World R is z up: down in the IMU frame S is R_RtoS · (−z).
  const Eigen::Vector3d down_true = gt.q_StoR.conjugate() * Eigen::Vector3d(0, 0, -1);
  const Eigen::Vector3d down_est =
      rotationBodyToNav<double>(init->euler).transpose() * Eigen::Vector3d::UnitZ();
  const double angle = std::acos(std::clamp(down_true.dot(down_est), -1.0, 1.0));
  EXPECT_LT(angle, 3.0 * init->tilt_sigma) << "tilt error " << angle << " rad";
  EXPECT_LT((init->gyro_bias - gt.gyro_bias).norm(), 0.005)
      << init->gyro_bias.transpose() << " vs " << gt.gyro_bias.transpose();
}

}  // namespace
}  // namespace cvslam
