// The mathematics of the INS/GPS filters checked numerically (thesis §3.4–3.6): the EKF's
// Jacobians F and H by finite differences, the SDC factorisation A(x)x + b = f(x) and
// H(x)x = h(x), the Riccati solution against its equation, and the H∞ correction (block form
// of eqs. 3.49–3.50 = information form; γ → ∞ gives the EKF).

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>

#include "cvslam/core/random.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_ekf.h"
#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/insgps/nhinf_gps_filter.h"
#include "cvslam/insgps/riccati.h"
#include "cvslam/insgps/sdc_factorisation.h"
#include "jacobian_check.h"

namespace cvslam::insgps {
namespace {

/// A random flight-like state: position ±200 m, body velocity ±15 m/s, roll/pitch ±40°,
/// any yaw.
StateVector randomState(Rng& rng) {
  StateVector x;
  for (int i = 0; i < 3; ++i) x(i) = rng.uniform(-200.0, 200.0);
  for (int i = 3; i < 6; ++i) x(i) = rng.uniform(-15.0, 15.0);
  x(6) = rng.uniform(-0.7, 0.7);
  x(7) = rng.uniform(-0.7, 0.7);
  x(8) = rng.uniform(-M_PI, M_PI);
  return x;
}

ImuSample randomImu(Rng& rng, int64_t t_us) {
  ImuSample s;
  s.t_us = t_us;
  for (int i = 0; i < 3; ++i) s.gyro_B(i) = rng.uniform(-1.0, 1.0);
  for (int i = 0; i < 3; ++i) s.accel_B(i) = rng.uniform(-5.0, 5.0);
  s.accel_B.z() -= 9.81;
  return s;
}

TEST(InsGpsMath, GpsJacobianMatchesFiniteDifferences) {
  Rng rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const StateVector x = randomState(rng);
    auto h = [](const Eigen::VectorXd& z) { return Eigen::VectorXd(gpsPredicted(StateVector(z))); };
    EXPECT_TRUE(cvslam::test::jacobianMatches(h, x, Eigen::MatrixXd(gpsJacobian(x)), 1e-6, 1e-7));
  }
}

TEST(InsGpsMath, EkfTransitionMatchesFiniteDifferencesOfTheMechanisation) {
  // F = ∂x₁/∂x₀ and Γ = ∂x₁/∂w of the RK4 step the EKF (and KF, NH∞) use, eq. 3.20.
  const InsPropagator prop(insgpsPropagatorOptions({}));
  Rng rng(2);
  for (int trial = 0; trial < 10; ++trial) {
    const StateVector x = randomState(rng);
    const ImuSample s0 = randomImu(rng, 0), s1 = randomImu(rng, 5000);
    Eigen::VectorXd x1;
    Eigen::MatrixXd F, G, Q;
    ASSERT_TRUE(prop.step(x, s0, s1, &x1, &F, &G, &Q).ok());
    const Eigen::VectorXd w0 = Eigen::VectorXd::Zero(kNoiseSize);
    auto fx = [&](const Eigen::VectorXd& z) { return prop.stepMean(z, s0, s1, w0); };
    auto fw = [&](const Eigen::VectorXd& w) { return prop.stepMean(x, s0, s1, w); };
    EXPECT_TRUE(cvslam::test::jacobianMatches(fx, x, F, 1e-5, 1e-7));
    // w enters almost linearly: a larger step keeps the 200 m positions' round-off out.
    EXPECT_TRUE(cvslam::test::jacobianMatches(fw, w0, G, 1e-5, 1e-9, 1e-3));
  }
}

TEST(InsGpsMath, SdcFactorisationReproducesTheDynamicsAndObservation) {
  Rng rng(3);
  const double g = 9.81;
  for (double alpha : {0.0, 0.5, 1.0, 1.7}) {  // any α gives an SDC form (§3.7.1)
    for (int trial = 0; trial < 20; ++trial) {
      StateVector x = randomState(rng);
      if (trial == 0) x(6) = 1e-9;  // the small-coordinate branch (partial derivative)
      const ImuSample s = randomImu(rng, 0);
      const InsSdc sdc = insSdc(x, s, g, alpha);
      const StateVector f = insDynamics(x, s, g);
      EXPECT_LT((sdc.A * x + sdc.b - f).norm(), 1e-9 * (1.0 + f.norm())) << alpha;
      EXPECT_LT((sdc.H * x - gpsPredicted(x)).norm(), 1e-9 * (1.0 + x.norm())) << alpha;
      // b is f at the origin: the affine part, independent of x.
      EXPECT_LT((sdc.b - insDynamics(StateVector::Zero(), s, g)).norm(), 1e-12);
    }
  }
}

TEST(InsGpsMath, StaircaseSdcIsExactAndTendsToTheJacobianAtTheOrigin) {
  const AttitudeFunction c = [](const Eigen::Vector3d& a) {
    return Eigen::Vector3d(std::sin(a.x()) * std::cos(a.y()), a.y() * a.z() + std::sin(a.z()),
                           std::exp(a.x() * a.z()) - 1.0);
  };
  const Eigen::Vector3d e(0.3, -0.4, 0.8);
  for (const auto& order : {kForwardOrder, kReverseOrder}) {
    EXPECT_LT((staircaseSdc(c, e, order) * e - c(e)).norm(), 1e-12);
  }
  // The two orders are different factorisations of the same function.
  EXPECT_GT((staircaseSdc(c, e, kForwardOrder) - staircaseSdc(c, e, kReverseOrder)).norm(), 1e-3);
  // Near 0 the SDC matrix tends to the Jacobian at 0.
  const Eigen::Vector3d tiny = 1e-5 * e;
  auto cv = [&](const Eigen::VectorXd& z) { return Eigen::VectorXd(c(Eigen::Vector3d(z))); };
  const Eigen::MatrixXd J0 = cvslam::test::numericalJacobian(cv, Eigen::Vector3d::Zero());
  EXPECT_LT((staircaseSdc(c, tiny, kForwardOrder) - J0).norm(), 1e-4);
}

TEST(InsGpsMath, RiccatiSolutionSatisfiesItsEquation) {
  Rng rng(4);
  const double g = 9.81;
  for (int trial = 0; trial < 10; ++trial) {
    const StateVector x = randomState(rng);
    const ImuSample s = randomImu(rng, 0);
    const InsSdc sdc = insSdc(x, s, g, 0.5);
    const double T = 0.2;
    const StateMatrix Phi = 0.999 * StateMatrix((sdc.A * T).exp());
    StateMatrix Q = StateMatrix::Zero();
    Q.block<6, 6>(3, 3) = 1e-4 * Eigen::Matrix<double, 6, 6>::Identity();
    MeasVector r;
    r << 2.25, 2.25, 9.0, 0.01, 0.01, 0.01;
    const MeasMatrix R = r.asDiagonal();
    auto sol = solveFilterDare(Phi, sdc.H, R, Q);
    ASSERT_TRUE(sol.ok()) << sol.status().message();
    const StateMatrix& P = sol->P;
    // Quadratic convergence: 2^k steps of the Riccati recursion after k doublings; the 0.999
    // mode needs ~2^13 of them.
    EXPECT_LE(sol->iterations, 25);
    EXPECT_LT(filterDareResidual(P, Phi, sdc.H, R, Q).norm(), 1e-8 * (1.0 + P.norm()));
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<StateMatrix>(P).eigenvalues()(0), -1e-10);
    // Stabilising: the closed loop Φ (I − K H) has its eigenvalues inside the unit circle.
    const MeasMatrix S = sdc.H * P * sdc.H.transpose() + R;
    const Eigen::Matrix<double, kStateSize, kMeasSize> K = P * sdc.H.transpose() * S.inverse();
    const StateMatrix closed = Phi * (StateMatrix::Identity() - K * sdc.H);
    EXPECT_LT(closed.eigenvalues().cwiseAbs().maxCoeff(), 1.0);
    // The same P as iterating the Riccati recursion to convergence.
    StateMatrix Pi = Q;
    for (int k = 0; k < 20000; ++k) {
      const MeasMatrix Si = sdc.H * Pi * sdc.H.transpose() + R;
      Pi = Phi * Pi * Phi.transpose() -
           Phi * Pi * sdc.H.transpose() * Si.inverse() * sdc.H * Pi * Phi.transpose() + Q;
    }
    EXPECT_LT((Pi - P).norm(), 1e-6 * P.norm());
  }
}

TEST(InsGpsMath, RiccatiReportsAnUndetectablePair) {
  // A mode growing (|λ| > 1) that H cannot see: no stabilising solution.
  StateMatrix Phi = StateMatrix::Identity();
  Phi(8, 8) = 1.5;
  MeasJacobian H = MeasJacobian::Zero();
  H.block<6, 6>(0, 0).setIdentity();
  const StateMatrix Q = StateMatrix::Identity();
  EXPECT_FALSE(solveFilterDare(Phi, H, MeasMatrix::Identity(), Q).ok());
}

TEST(InsGpsMath, HinfBlockFormEqualsInformationForm) {
  Rng rng(5);
  const StateVector x = randomState(rng);
  const MeasJacobian H = gpsJacobian(x);
  Eigen::Matrix<double, kStateSize, kStateSize> M;
  for (int i = 0; i < kStateSize * kStateSize; ++i) M(i) = rng.uniform(-1.0, 1.0);
  const StateMatrix P = 0.1 * M * M.transpose() + 0.05 * StateMatrix::Identity();
  MeasVector r;
  r << 2.25, 2.25, 9.0, 0.01, 0.01, 0.01;
  const MeasMatrix R = r.asDiagonal();
  const double theta = 0.01;
  const StateMatrix info =
      (P.inverse() - theta * StateMatrix::Identity() + H.transpose() * R.inverse() * H).inverse();
  EXPECT_LT((hinfPosteriorBlockForm(P, H, R, theta) - info).norm(), 1e-9 * info.norm());
}

TEST(InsGpsMath, NhinfTendsToTheEkfAsGammaGrows) {
  NhinfOptions o;
  o.gamma = 1e8;
  o.delta1 = o.delta2 = o.delta3 = 0.0;
  NhinfGpsFilter hinf({}, o);
  GpsAidedEkf ekf({}, {});
  Rng rng(6);
  StateVector x0 = randomState(rng);
  StateMatrix P0 = StateMatrix::Identity();
  P0.diagonal().segment<3>(6).setConstant(1e-3);
  hinf.initialize(x0, P0, 0);
  ekf.initialize(x0, P0, 0);
  ImuSample s0 = randomImu(rng, 0);
  for (int k = 1; k <= 40; ++k) {
    ImuSample s1 = randomImu(rng, 5000 * k);
    ASSERT_TRUE(hinf.propagate(s0, s1).ok());
    ASSERT_TRUE(ekf.propagate(s0, s1).ok());
    s0 = s1;
  }
  GpsFix fix;
  fix.t_us = s0.t_us;
  fix.p_N = x0.head<3>() + Eigen::Vector3d(1.0, -2.0, 0.5);
  fix.v_N = Eigen::Vector3d(3.0, 1.0, 0.0);
  ASSERT_TRUE(hinf.update(fix).ok());
  ASSERT_TRUE(ekf.update(fix).ok());
  EXPECT_LT(stateDifference(hinf.state(), ekf.state()).norm(), 1e-6);
  EXPECT_LT((hinf.covariance() - ekf.covariance()).norm(), 1e-6 * ekf.covariance().norm());
  // A finite γ gives a larger (more cautious) posterior than the EKF's.
  NhinfOptions robust;
  NhinfGpsFilter h2({}, robust);
  h2.initialize(x0, P0, 0);
  ASSERT_TRUE(h2.update(fix).ok());
  GpsAidedEkf e2({}, {});
  e2.initialize(x0, P0, 0);
  ASSERT_TRUE(e2.update(fix).ok());
  EXPECT_GT(h2.covariance().trace(), e2.covariance().trace());
}

}  // namespace
}  // namespace cvslam::insgps
