// IMU synthesis (cvslam/sim/imu_simulator.h): sign conventions (docs/conventions.md), integration
// of the noise-free IMU back to the trajectory, white-noise and bias random-walk statistics.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "cvslam/scenario/position_path.h"
#include "cvslam/scenario/tum_trajectory.h"
#include "cvslam/sim/imu_simulator.h"
#include "sim_test_helpers.h"
#include "test_paths.h"

namespace cvslam::sim {
namespace {

using simtest::integrateImu;
using simtest::makeFlight;

TEST(SimImu, LevelHoverReadsMinusGravity) {
  auto traj = makeFlight(std::make_shared<HoverPath>(Eigen::Vector3d(1, 2, -10)));
  ImuOptions o;
  o.noise = false;
  ImuSimulator imu(traj, o, 1);
  for (int64_t t = 0; t < 1000000; t += 5000) {
    const ImuSample s = imu.sample(t);
    EXPECT_LT((s.accel_B - Eigen::Vector3d(0, 0, -9.81)).norm(), 1e-12);
    EXPECT_LT(s.gyro_B.norm(), 1e-12);
  }
}

TEST(SimImu, NoiseFreeIntegrationReproducesTrajectory) {
  LoopPath::Params loop;
  loop.semi_axis_x = 60;
  loop.semi_axis_y = 40;
  loop.altitude_amplitude = 2.0;
  loop.period = 60;
  Figure8Path::Params f8;
  f8.period = 30;
  const std::vector<Eigen::Vector3d> wps = {{0, 0, -10},   {20, 5, -11}, {40, -5, -12},
                                            {60, 10, -10}, {80, 0, -9},  {90, 20, -10}};
  const std::vector<std::shared_ptr<const Trajectory>> trajs = {
      makeFlight(std::make_shared<LoopPath>(loop)), makeFlight(std::make_shared<Figure8Path>(f8)),
      makeFlight(std::make_shared<SplinePath>(SplinePath::chordTimes(wps, 3), wps, false))};
  for (std::size_t i = 0; i < trajs.size(); ++i) {
    SCOPED_TRACE(i);
    const double t1 = 30.0;
    const simtest::NavState x = integrateImu(*trajs[i], 0.0, t1, 2e-3);
    const TrajectoryState truth = trajs[i]->state(t1);
    EXPECT_LT((x.p_N - truth.p_BinN).norm(), 1e-3);
    EXPECT_LT((x.v_N - truth.v_N).norm(), 1e-4);
    EXPECT_LT((x.R_BtoN - truth.R_NtoB.transpose()).norm(), 1e-6);
  }
}

TEST(SimImu, NoiseFreeIntegrationReproducesTumTrajectory) {
  // EuRoC ground truth through the TUM splines: ω from the quaternion spline's derivative and
  // f from the position spline integrate back to the same trajectory.
  TumTrajectoryOptions o;
  o.file = cvslam::test::sharedDataDir() + "/euroc/V1_01_easy.tum";
  auto traj = TumTrajectory::load(o);
  ASSERT_TRUE(traj.ok()) << traj.status().message();
  const double t0 = 10.0, t1 = 40.0;
  const simtest::NavState x = integrateImu(**traj, t0, t1, 1e-3);
  const TrajectoryState truth = (*traj)->state(t1);
  EXPECT_LT((x.p_N - truth.p_BinN).norm(), 1e-6);
  EXPECT_LT((x.R_BtoN - truth.R_NtoB.transpose()).norm(), 1e-6);
}

TEST(SimImu, WrongGravitySignWouldBeCaught) {
  // The integration of NoiseFreeIntegrationReproducesTrajectory, fed the simulator's samples
  // with the gravity sign of the specific force flipped (f = R_NtoB (a + g) instead of
  // R_NtoB (a − g)), drifts by metres where the right sign stays within 1 mm: that test can
  // fail on the convention it checks.
  LoopPath::Params loop;
  loop.period = 60;
  auto traj = makeFlight(std::make_shared<LoopPath>(loop));
  const double t1 = 5.0;
  const simtest::NavState right = integrateImu(*traj, 0.0, t1, 1e-3);
  const simtest::NavState wrong = integrateImu(*traj, 0.0, t1, 1e-3, [](const TrajectoryState& s) {
    ImuSample m = ImuSimulator::perfectSample(s, 0);
    m.accel_B += 2.0 * s.R_NtoB * gravityNed();
    return m;
  });
  const Eigen::Vector3d truth = traj->state(t1).p_BinN;
  EXPECT_LT((right.p_N - truth).norm(), 1e-3);
  EXPECT_GT((wrong.p_N - truth).norm(), 10.0);
}

TEST(SimImu, WhiteNoiseAndBiasRandomWalkStatistics) {
  auto traj = makeFlight(std::make_shared<HoverPath>(Eigen::Vector3d(0, 0, -10)));
  ImuOptions o;
  o.rate_hz = 200;
  o.gyro_noise_density = 1e-3;
  o.accel_noise_density = 2e-2;
  o.gyro_random_walk = 0.0;
  o.accel_random_walk = 0.0;
  o.accel_bias = Eigen::Vector3d(0.1, -0.2, 0.3);
  {
    ImuSimulator imu(traj, o, 42);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d e = imu.sample(k * 5000).accel_B - Eigen::Vector3d(0, 0, -9.81);
      sum += e;
      sum2 += e.cwiseProduct(e);
    }
    const Eigen::Vector3d mean = sum / n;
    const Eigen::Vector3d stdv = (sum2 / n - mean.cwiseProduct(mean)).cwiseSqrt();
    const double expected = 2e-2 * std::sqrt(200.0);
    EXPECT_LT((mean - o.accel_bias).norm(), 5 * expected / std::sqrt(n));
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(stdv(i), expected, 0.03 * expected);
  }
  // Bias random walk: Var(b(T) − b(0)) = σ_rw² T, over many independent streams.
  o.gyro_noise_density = o.accel_noise_density = 0.0;
  o.gyro_random_walk = 1e-3;
  o.accel_bias.setZero();
  const int runs = 400;
  const double T = 10.0;
  double sum2 = 0.0;
  for (int r = 0; r < runs; ++r) {
    ImuSimulator imu(traj, o, 1000 + r);
    for (int64_t t = 0; t <= static_cast<int64_t>(T * 1e6); t += 5000) imu.sample(t);
    sum2 += imu.gyroBias().squaredNorm();
  }
  const double var = sum2 / (3 * runs);
  const double expected_var = 1e-6 * T;
  EXPECT_NEAR(var, expected_var, 0.15 * expected_var);
}

TEST(SimImu, NonGaussianCentredNoiseHasSameSigma) {
  auto traj = makeFlight(std::make_shared<HoverPath>(Eigen::Vector3d(0, 0, -10)));
  ImuOptions o;
  o.kind = NoiseKind::kNonGaussianCentred;
  o.gyro_random_walk = o.accel_random_walk = 0.0;
  o.gyro_noise_density = 1e-3;
  ImuSimulator imu(traj, o, 5);
  double sum = 0, sum2 = 0, max_abs = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double e = imu.sample(k * 5000).gyro_B.x();
    sum += e;
    sum2 += e * e;
    max_abs = std::max(max_abs, std::abs(e));
  }
  const double sigma = 1e-3 * std::sqrt(200.0);
  EXPECT_NEAR(sum / n, 0.0, 5 * sigma / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum2 / n), sigma, 0.03 * sigma);
  EXPECT_LE(max_abs, std::sqrt(3.0) * sigma + 1e-12);  // uniform: bounded support
}

// Real-data check of the conventions: the IMU synthesised from EuRoC V1_02_medium's ground
// truth (body = IMU) agrees with the real ADIS16448 recording up to its biases (gyro bias of
// that sequence ≈ [−0.002 0.021 0.076] rad/s), vibration and noise.
TEST(SimImu, SynthesisedFromEurocGroundTruthMatchesRealImu) {
  const std::string dir = cvslam::test::sharedDataDir() + "/euroc/";
  TumTrajectoryOptions o;
  o.file = dir + "V1_02_medium.tum";
  auto traj = TumTrajectory::load(o);
  ASSERT_TRUE(traj.ok()) << traj.status().message();
  std::ifstream in(dir + "imu/V1_02_medium_imu0.csv");
  ASSERT_TRUE(in.good());
  std::string line;
  std::getline(in, line);  // header
  Eigen::Vector3d sum_g = Eigen::Vector3d::Zero(), sum_a = sum_g, sum_g2 = sum_g, sum_a2 = sum_g;
  int n = 0;
  while (std::getline(in, line)) {
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream ss(line);
    long long t_ns = 0;
    Eigen::Vector3d w, a;
    if (!(ss >> t_ns >> w.x() >> w.y() >> w.z() >> a.x() >> a.y() >> a.z())) continue;
    const double t = static_cast<double>(t_ns) * 1e-9 - (*traj)->startTime();
    if (t < 1.0 || t > (*traj)->duration() - 1.0) continue;
    const ImuSample m = ImuSimulator::perfectSample((*traj)->state(t), 0);
    const Eigen::Vector3d dg = w - m.gyro_B, da = a - m.accel_B;
    sum_g += dg;
    sum_a += da;
    sum_g2 += dg.cwiseProduct(dg);
    sum_a2 += da.cwiseProduct(da);
    ++n;
  }
  ASSERT_GT(n, 10000);
  const Eigen::Vector3d mean_g = sum_g / n, mean_a = sum_a / n;
  const Eigen::Vector3d std_g = (sum_g2 / n - mean_g.cwiseProduct(mean_g)).cwiseSqrt();
  const Eigen::Vector3d std_a = (sum_a2 / n - mean_a.cwiseProduct(mean_a)).cwiseSqrt();
  EXPECT_LT((mean_g - Eigen::Vector3d(-0.002, 0.021, 0.076)).norm(), 0.01) << mean_g.transpose();
  EXPECT_LT(std_g.maxCoeff(), 0.1) << std_g.transpose();  // real rates: 0.3–0.5 rad/s rms
  EXPECT_LT(mean_a.cwiseAbs().maxCoeff(), 0.2) << mean_a.transpose();  // a sign error: ~2g
  EXPECT_LT(std_a.maxCoeff(), 1.5) << std_a.transpose();  // EuRoC's vibration ≈ 1 m/s²
}

}  // namespace
}  // namespace cvslam::sim
