#include "cvslam/ins/ins_propagator.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <random>

#include "cvslam/geometry/so3.h"
#include "cvslam/io/config_node.h"
#include "jacobian_check.h"

namespace cvslam {
namespace {

/// A known, non-trivial motion: body rates and specific force varying in time, 200 Hz.
std::vector<ImuSample> knownMotion(double duration_s, int64_t period_us = 5000) {
  std::vector<ImuSample> samples;
  for (int64_t t = 0; t <= static_cast<int64_t>(duration_s * 1e6); t += period_us) {
    const double s = 1e-6 * static_cast<double>(t);
    ImuSample m;
    m.t_us = 1'000'000 + t;
    m.gyro_B = {0.2 * std::sin(s), 0.1, -0.3 * std::cos(2 * s)};
    m.accel_B = {0.5 + 0.3 * std::cos(s), -0.2, -9.5 + 0.4 * std::sin(3 * s)};
    samples.push_back(m);
  }
  return samples;
}

Eigen::VectorXd movingState(bool with_bias) {
  Eigen::VectorXd x(vehicle::size(with_bias));
  x.head<9>() << 1.0, -2.0, -10.0, 2.0, 0.5, -0.3, 0.1, -0.05, 0.3;
  if (with_bias) x.tail<6>() << 0.05, -0.03, 0.02, 0.004, -0.002, 0.003;
  return x;
}

/// Options with the thesis's Euler attitude.
InsPropagatorOptions eulerOptions() {
  InsPropagatorOptions o;
  o.attitude = vehicle::Attitude::kEuler;
  return o;
}

/// Options with the rotation error state.
InsPropagatorOptions errorStateOptions() {
  InsPropagatorOptions o;
  o.attitude = vehicle::Attitude::kErrorState;
  return o;
}

/// A state of the error-state INS: the moving state's Euler angles become the nominal.
struct ErrorState {
  Eigen::VectorXd x;
  Eigen::Quaterniond q;
};
ErrorState errorState(const InsPropagator& ins, const Eigen::VectorXd& x_euler) {
  ErrorState e;
  ins.fromEulerLayout(x_euler, &e.x, &e.q);
  return e;
}

/// x ⊟ reference of two error-state INS states: additive entries, and the attitude entries
/// Log(R̂_refᵀ R̂) (both δθ zero after a step).
Eigen::VectorXd boxMinus(const ErrorState& a, const ErrorState& ref) {
  Eigen::VectorXd d = a.x - ref.x;
  d.segment<3>(vehicle::kAttitude) = so3::log((ref.q.inverse() * a.q).toRotationMatrix());
  return d;
}

class InsPropagatorBias : public ::testing::TestWithParam<bool> {};

TEST_P(InsPropagatorBias, StepJacobiansMatchCentralDifferences) {
  InsPropagatorOptions o = eulerOptions();
  o.estimate_imu_bias = GetParam();
  const InsPropagator ins(o);
  const auto samples = knownMotion(0.01);
  const ImuSample &s0 = samples[0], &s1 = samples[1];
  const Eigen::VectorXd x0 = movingState(o.estimate_imu_bias);
  Eigen::VectorXd x1;
  Eigen::MatrixXd F, G, Q;
  ASSERT_TRUE(ins.step(x0, s0, s1, &x1, &F, &G, &Q).ok());
  const Eigen::VectorXd w0 = Eigen::VectorXd::Zero(ins.noiseSize());
  EXPECT_TRUE(x1.isApprox(ins.stepMean(x0, s0, s1, w0), 1e-14));
  EXPECT_TRUE(test::jacobianMatches(
      [&](const Eigen::VectorXd& x) { return ins.stepMean(x, s0, s1, w0); }, x0, F, 1e-6, 1e-8));
  EXPECT_TRUE(test::jacobianMatches(
      [&](const Eigen::VectorXd& w) { return ins.stepMean(x0, s0, s1, w); }, w0, G, 1e-6, 1e-8));
  // Q_w is the zero-order-hold discretisation σ²/dt.
  EXPECT_NEAR(Q(0, 0), o.accel_noise_density * o.accel_noise_density / 0.005, 1e-15);
  EXPECT_NEAR(Q(3, 3), o.gyro_noise_density * o.gyro_noise_density / 0.005, 1e-15);
}

/// Error state: F and G are the Jacobians of x₀⊞δ ↦ step(x₀⊞δ)⊟step(x₀), with ⊞ adding δ to
/// every entry (δθ in the chart about R̂) and ⊟ as boxMinus.
TEST_P(InsPropagatorBias, ErrorStateStepJacobiansMatchCentralDifferences) {
  InsPropagatorOptions o = errorStateOptions();
  o.estimate_imu_bias = GetParam();
  const InsPropagator ins(o);
  const auto samples = knownMotion(0.01);
  const ImuSample &s0 = samples[0], &s1 = samples[1];
  const ErrorState e0 = errorState(ins, movingState(o.estimate_imu_bias));
  ErrorState e1;
  Eigen::MatrixXd F, G, Q;
  ASSERT_TRUE(ins.step(e0.x, e0.q, s0, s1, &e1.x, &e1.q, &F, &G, &Q).ok());
  EXPECT_EQ(e1.x.segment<3>(vehicle::kAttitude), Eigen::Vector3d::Zero());
  const Eigen::VectorXd w0 = Eigen::VectorXd::Zero(ins.noiseSize());
  const auto stepped = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& w) {
    ErrorState e;
    e.x = ins.stepMean(x, e0.q, s0, s1, w, &e.q);
    return boxMinus(e, e1);
  };
  EXPECT_LT(stepped(e0.x, w0).norm(), 1e-14);
  EXPECT_TRUE(test::jacobianMatches([&](const Eigen::VectorXd& x) { return stepped(x, w0); }, e0.x,
                                    F, 1e-6, 1e-8));
  EXPECT_TRUE(test::jacobianMatches([&](const Eigen::VectorXd& w) { return stepped(e0.x, w); }, w0,
                                    G, 1e-6, 1e-8));
  // The same from a non-zero δθ (a state mid-update): the chart carries it.
  Eigen::VectorXd x_off = e0.x;
  x_off.segment<3>(vehicle::kAttitude) << 0.02, -0.01, 0.03;
  ErrorState e1_off;
  ASSERT_TRUE(ins.step(x_off, e0.q, s0, s1, &e1_off.x, &e1_off.q, &F, &G, &Q).ok());
  const auto stepped_off = [&](const Eigen::VectorXd& x) {
    ErrorState e;
    e.x = ins.stepMean(x, e0.q, s0, s1, w0, &e.q);
    return boxMinus(e, e1_off);
  };
  EXPECT_TRUE(test::jacobianMatches(stepped_off, x_off, F, 1e-6, 1e-8));
}

/// Pitch ±90° (IMU x axis vertical, as the EuRoC VI-sensor mounts it): a constant body rate
/// about y carries the vehicle through pitch 90°. The error state follows the exact rotation
/// R₀ Exp(ω t); the Euler model refuses at the singularity (eq. 2.4).
TEST(InsPropagator, ErrorStateCrossesPitch90WhereEulerFails) {
  const Eigen::Vector3d omega(0.0, 0.5, 0.0);
  std::vector<ImuSample> samples;
  for (int k = 0; k <= 400; ++k) {  // 2 s at 200 Hz: pitch 80° → 137°
    ImuSample m;
    m.t_us = int64_t{5000} * k;
    m.gyro_B = omega;
    samples.push_back(m);
  }
  Eigen::VectorXd x_euler = Eigen::VectorXd::Zero(9);
  x_euler(vehicle::kAttitude + 1) = 80.0 * M_PI / 180.0;
  const InsPropagator euler_ins(eulerOptions());
  InsTransition tr;
  const Status s = euler_ins.propagate(x_euler, samples, &tr);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("singularity"), std::string::npos) << s.message();

  const InsPropagator ins(errorStateOptions());
  const ErrorState e0 = errorState(ins, x_euler);
  ASSERT_TRUE(ins.propagate(e0.x, e0.q, samples, &tr).ok());
  const Eigen::Matrix3d R_true =
      e0.q.toRotationMatrix() * so3::exp<double>(Eigen::Vector3d(omega * 2.0));
  EXPECT_LT(so3::log(R_true.transpose() * tr.q_BtoN.toRotationMatrix()).norm(), 1e-9);
  EXPECT_EQ(tr.x.segment<3>(vehicle::kAttitude), Eigen::Vector3d::Zero());
  EXPECT_TRUE(tr.Phi.allFinite());
  EXPECT_TRUE(tr.Qd.allFinite());
  // Starting exactly at pitch 90° is fine too.
  Eigen::VectorXd x_up = Eigen::VectorXd::Zero(9);
  const Eigen::Quaterniond q_up(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));
  ASSERT_TRUE(ins.propagate(x_up, q_up, samples, &tr).ok());
  EXPECT_LT(
      so3::log(
          (q_up.toRotationMatrix() * so3::exp<double>(Eigen::Vector3d(omega * 2.0))).transpose() *
          tr.q_BtoN.toRotationMatrix())
          .norm(),
      1e-9);
}

TEST(InsPropagator, DynamicsMatchEquation25WithCorrectedGravitySign) {
  // Thesis eq. 2.5 written out per component, with the gravity sign of docs/conventions.md
  // (the thesis prints +g sinθ, −g cosθ sinφ, −g cosθ cosφ).
  Eigen::Matrix<double, 9, 1> x;
  x << 1.0, -2.0, -10.0, 2.0, 0.5, -0.3, 0.1, -0.05, 0.3;
  const Eigen::Vector3d gyro(0.2, 0.1, -0.3), accel(0.5, -0.2, -9.5);
  const auto xdot =
      InsPropagator::dynamics<double, 9>(x, gyro, accel, Eigen::Matrix<double, 6, 1>::Zero(), 9.81);
  const double U = x(3), V = x(4), W = x(5), phi = x(6), theta = x(7);
  const double p = gyro(0), q = gyro(1), r = gyro(2), g = 9.81;
  EXPECT_NEAR(xdot(3), accel(0) + V * r - W * q - g * std::sin(theta), 1e-12);
  EXPECT_NEAR(xdot(4), accel(1) - U * r + W * p + g * std::cos(theta) * std::sin(phi), 1e-12);
  EXPECT_NEAR(xdot(5), accel(2) + U * q - V * p + g * std::cos(theta) * std::cos(phi), 1e-12);
  // Position rate is R_BtoN v_B (eq. 2.7) and attitude rates eq. 2.4.
  const Eigen::Vector3d euler = x.segment<3>(6);
  EXPECT_TRUE(xdot.head<3>().isApprox(rotationBodyToNav(euler) * x.segment<3>(3), 1e-12));
  EXPECT_TRUE(xdot.tail<3>().isApprox(eulerRates(euler, gyro), 1e-12));
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutBias, InsPropagatorBias, ::testing::Bool());

TEST(InsPropagator, LevelAtRestStaysAtRest) {
  // docs/conventions.md sign convention: a level IMU at rest reads f_B = [0 0 −g].
  const InsPropagator ins(eulerOptions());
  std::vector<ImuSample> samples(101);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    samples[k].t_us = static_cast<int64_t>(k) * 5000;
    samples[k].accel_B = {0.0, 0.0, -9.81};
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(9);
  x(vehicle::kAttitude + 2) = 0.7;  // any heading
  InsTransition tr;
  ASSERT_TRUE(ins.propagate(x, samples, &tr).ok());
  EXPECT_TRUE(tr.x.isApprox(x, 1e-12)) << tr.x.transpose();
  EXPECT_EQ(tr.t_us, 500000);
  // Free fall (f_B = 0) accelerates downwards (+Z in NED) at g.
  for (auto& s : samples) s.accel_B.setZero();
  ASSERT_TRUE(ins.propagate(Eigen::VectorXd::Zero(9), samples, &tr).ok());
  EXPECT_NEAR(tr.x(vehicle::kPosition + 2), 0.5 * 9.81 * 0.25, 1e-9);
  EXPECT_NEAR(tr.x(vehicle::kVelocity + 2), 9.81 * 0.5, 1e-9);
}

TEST(InsPropagator, RejectsBadTimestampsAndSizes) {
  const InsPropagator ins(eulerOptions());
  auto samples = knownMotion(0.02);
  InsTransition tr;
  const Eigen::VectorXd x = movingState(false);
  ASSERT_TRUE(ins.propagate(x, samples, &tr).ok());
  auto repeated = samples;
  repeated[2].t_us = repeated[1].t_us;
  EXPECT_FALSE(ins.propagate(x, repeated, &tr).ok());
  auto backwards = samples;
  backwards[2].t_us = backwards[1].t_us - 10;
  EXPECT_FALSE(ins.propagate(x, backwards, &tr).ok());
  auto gap = samples;
  gap[3].t_us += 200000;  // 0.2 s > max_dt
  const Status s = ins.propagate(x, gap, &tr);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_dt"), std::string::npos) << s.message();
  EXPECT_FALSE(ins.propagate(movingState(true), samples, &tr).ok());
  Eigen::VectorXd gimbal_lock = x;
  gimbal_lock(vehicle::kAttitude + 1) = M_PI / 2;
  EXPECT_FALSE(ins.propagate(gimbal_lock, samples, &tr).ok());
  auto nan_sample = samples;
  nan_sample[2].gyro_B.x() = std::nan("");
  EXPECT_FALSE(ins.propagate(x, nan_sample, &tr).ok());
  EXPECT_FALSE(ins.propagate(x, {}, &tr).ok());
}

TEST(InsPropagator, SplittingAnIntervalAtAnInterpolatedSampleMatches) {
  // Propagating to a camera time between two IMU samples and on from there equals the
  // single step to within the RK4 error (inputs are linear in time either way).
  const InsPropagator ins(eulerOptions());
  const auto samples = knownMotion(0.005);
  const ImuSample mid = interpolateImu(samples[0], samples[1], samples[0].t_us + 2000);
  EXPECT_EQ(mid.t_us, samples[0].t_us + 2000);
  EXPECT_TRUE(mid.gyro_B.isApprox(0.6 * samples[0].gyro_B + 0.4 * samples[1].gyro_B, 1e-15));
  InsTransition whole, first, second;
  const Eigen::VectorXd x = movingState(false);
  ASSERT_TRUE(ins.propagate(x, {samples[0], samples[1]}, &whole).ok());
  ASSERT_TRUE(ins.propagate(x, {samples[0], mid}, &first).ok());
  ASSERT_TRUE(ins.propagate(first.x, {mid, samples[1]}, &second).ok());
  EXPECT_TRUE(second.x.isApprox(whole.x, 1e-10));
  EXPECT_TRUE((second.Phi * first.Phi).isApprox(whole.Phi, 1e-8));
}

TEST(InsPropagatorOptions, LoadsAndValidates) {
  auto cfg = ConfigNode::fromString(
      "ins: {gyro_noise_density: 0.01, estimate_imu_bias: true, max_dt: 0.05}", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  InsPropagatorOptions o;
  ASSERT_TRUE(o.load(cfg->child("ins")).ok());
  EXPECT_DOUBLE_EQ(o.gyro_noise_density, 0.01);
  EXPECT_TRUE(o.estimate_imu_bias);
  EXPECT_DOUBLE_EQ(o.max_dt, 0.05);
  EXPECT_TRUE(cfg->finish().ok());
  auto bad = ConfigNode::fromString("{accel_noise_density: -1}", "t.yaml");
  InsPropagatorOptions o2;
  const Status s = o2.load(*bad);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "t.yaml: accel_noise_density: must be > 0");

  // print() round-trips through load().
  o.gravity = 9.80665;
  auto printed = ConfigNode::fromString(o.print(), "printed");
  ASSERT_TRUE(printed.ok()) << o.print();
  InsPropagatorOptions back;
  ASSERT_TRUE(back.load(*printed).ok());
  EXPECT_TRUE(printed->finish().ok());
  EXPECT_EQ(back.print(), o.print());
  EXPECT_EQ(back.gravity, 9.80665);
  EXPECT_TRUE(back.estimate_imu_bias);
  EXPECT_EQ(back.attitude, vehicle::Attitude::kErrorState);  // the default
  auto error_state = ConfigNode::fromString("{attitude: error_state}", "t.yaml");
  InsPropagatorOptions o3;
  ASSERT_TRUE(o3.load(*error_state).ok());
  EXPECT_EQ(o3.attitude, vehicle::Attitude::kErrorState);
  auto wrong = ConfigNode::fromString("{attitude: quaternion}", "t.yaml");
  EXPECT_EQ(o3.load(*wrong).message(), "t.yaml: attitude: must be error_state or euler");
}

TEST(InsPropagatorOptions, ScalesMultiplyTheDensitiesWhateverSetThem) {
  // noise_density_scale / random_walk_scale act on the densities a recording's sensor.yaml
  // sets too: the discrete variances grow by the squared factors, each on its own block.
  InsPropagatorOptions o;
  o.estimate_imu_bias = true;
  o.accel_noise_density = 0.02;  // as calibrationFromEuroc would set them
  o.gyro_random_walk = 2e-5;
  InsPropagatorOptions scaled = o;
  auto cfg = ConfigNode::fromString("{noise_density_scale: 2.0, random_walk_scale: 3.0}", "t.yaml");
  ASSERT_TRUE(cfg.ok());
  ASSERT_TRUE(scaled.load(*cfg).ok());
  EXPECT_DOUBLE_EQ(scaled.accel_noise_density, 0.02);
  const Eigen::VectorXd q = InsPropagator(o).noiseVariances(0.005);
  const Eigen::VectorXd qs = InsPropagator(scaled).noiseVariances(0.005);
  ASSERT_EQ(q.size(), 12);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(qs(i), 4.0 * q(i), 1e-12 * q(i)) << i;
  for (int i = 6; i < 12; ++i) EXPECT_NEAR(qs(i), 9.0 * q(i), 1e-12 * q(i)) << i;
  auto bad = ConfigNode::fromString("{random_walk_scale: 0}", "t.yaml");
  EXPECT_EQ(InsPropagatorOptions().load(*bad).message(), "t.yaml: random_walk_scale: must be > 0");

  // The datasheet factor multiplies the random walks only, on top of random_walk_scale.
  InsPropagatorOptions truth = o;
  truth.datasheet_random_walk_scale = 1.0;
  const Eigen::VectorXd qt = InsPropagator(truth).noiseVariances(0.005);
  const double f = o.datasheet_random_walk_scale;
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(q(i), qt(i), 1e-12 * q(i)) << i;
  for (int i = 6; i < 12; ++i) EXPECT_NEAR(q(i), f * f * qt(i), 1e-12 * q(i)) << i;
  auto bad_datasheet = ConfigNode::fromString("{datasheet_random_walk_scale: -1}", "t.yaml");
  EXPECT_EQ(InsPropagatorOptions().load(*bad_datasheet).message(),
            "t.yaml: datasheet_random_walk_scale: must be > 0");
}

/// Monte-Carlo check of the covariance propagation (GTSAM practice): sample
/// initial states from N(x0, P0) and the discrete noise from N(0, Q_w) at every step, push
/// each through the nonlinear RK4 model for 1 s, and compare the sampled error covariance
/// with Φ P0 Φᵀ + Qd from propagate().
void checkMonteCarloCovariance(bool with_bias, vehicle::Attitude attitude) {
  InsPropagatorOptions o;
  o.attitude = attitude;
  o.estimate_imu_bias = with_bias;
  const bool euler = attitude == vehicle::Attitude::kEuler;
  // Noisier than a real IMU so that process noise matters next to P0.
  o.accel_noise_density = 0.05;
  o.gyro_noise_density = 0.01;
  o.accel_random_walk = 0.02;
  o.gyro_random_walk = 0.002;
  const InsPropagator ins(o);
  const int n = ins.stateSize();
  const auto samples = knownMotion(1.0);
  const ErrorState e0 = errorState(ins, movingState(o.estimate_imu_bias));
  const Eigen::VectorXd& x0 = e0.x;
  Eigen::VectorXd sigma0(n);
  sigma0.head<9>() << 0.05, 0.05, 0.05, 0.03, 0.03, 0.03, 0.01, 0.01, 0.01;
  if (o.estimate_imu_bias) sigma0.tail<6>() << 0.02, 0.02, 0.02, 0.002, 0.002, 0.002;
  const Eigen::MatrixXd P0 = sigma0.array().square().matrix().asDiagonal();

  InsTransition nominal;
  ASSERT_TRUE(ins.propagate(x0, e0.q, samples, &nominal).ok());
  const Eigen::MatrixXd P1 = nominal.Phi * P0 * nominal.Phi.transpose() + nominal.Qd;
  // The process noise must matter, or a wrong G would go unnoticed.
  for (int i = vehicle::kVelocity; i < vehicle::kAttitude + 3; ++i) {
    ASSERT_GT(nominal.Qd(i, i), 0.2 * P1(i, i)) << "state " << i;
  }

  constexpr int kRuns = 2000;
  std::mt19937 rng(20261121);
  std::normal_distribution<double> normal;
  const Eigen::VectorXd q_std = ins.noiseVariances(0.005).cwiseSqrt();
  Eigen::MatrixXd errors(n, kRuns);
  Eigen::VectorXd w(ins.noiseSize());
  for (int r = 0; r < kRuns; ++r) {
    ErrorState e{Eigen::VectorXd(n), e0.q};
    for (int i = 0; i < n; ++i) e.x(i) = x0(i) + sigma0(i) * normal(rng);
    for (std::size_t k = 1; k < samples.size(); ++k) {
      for (int j = 0; j < w.size(); ++j) w(j) = q_std(j) * normal(rng);
      e.x = ins.stepMean(e.x, e.q, samples[k - 1], samples[k], w, &e.q);
    }
    if (euler) {
      errors.col(r) = e.x - nominal.x;
      errors(vehicle::kAttitude + 2, r) = wrapAngle(errors(vehicle::kAttitude + 2, r));
    } else {
      errors.col(r) = boxMinus(e, {nominal.x, nominal.q_BtoN});
    }
  }
  const Eigen::VectorXd mean = errors.rowwise().mean();
  const Eigen::MatrixXd centred = errors.colwise() - mean;
  const Eigen::MatrixXd P_sampled = centred * centred.transpose() / (kRuns - 1);
  // Variance of a sample variance is 2σ⁴/N: 15 % is > 4.5 standard errors for N = 2000.
  for (int i = 0; i < n; ++i) {
    const double ratio = P_sampled(i, i) / P1(i, i);
    EXPECT_GT(ratio, 0.85) << "state " << i;
    EXPECT_LT(ratio, 1.15) << "state " << i;
  }
  // Negative control: the same samples reject a process noise that is off by a factor 2,
  // so this test has the power to catch a wrong G or Q_w.
  const Eigen::MatrixXd P1_wrong = nominal.Phi * P0 * nominal.Phi.transpose() + 0.5 * nominal.Qd;
  double worst_wrong = 0.0;
  for (int i = 0; i < n; ++i) {
    worst_wrong = std::max(worst_wrong, std::abs(P_sampled(i, i) / P1_wrong(i, i) - 1.0));
  }
  EXPECT_GT(worst_wrong, 0.15);
  // Average NEES of the errors about the nominal trajectory ~ χ²(n·N)/N: mean n, standard
  // deviation sqrt(2n/N).
  const Eigen::LLT<Eigen::MatrixXd> llt(P1);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const double nees = llt.matrixL().solve(errors).colwise().squaredNorm().mean();
  EXPECT_NEAR(nees, n, 4.0 * std::sqrt(2.0 * n / kRuns)) << "average NEES";
}

TEST_P(InsPropagatorBias, MonteCarloCovarianceMatchesPropagatedCovariance) {
  checkMonteCarloCovariance(GetParam(), vehicle::Attitude::kEuler);
}

TEST_P(InsPropagatorBias, ErrorStateMonteCarloCovarianceMatchesPropagatedCovariance) {
  checkMonteCarloCovariance(GetParam(), vehicle::Attitude::kErrorState);
}

}  // namespace
}  // namespace cvslam
