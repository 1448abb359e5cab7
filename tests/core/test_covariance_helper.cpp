#include "cvslam/filter/covariance_helper.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <random>

#include "filter_fixtures.h"

namespace cvslam {
namespace {

using test::randomCovariance;
using test::randomMatrix;

double minEigenvalue(const Eigen::MatrixXd& P) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .minCoeff();
}

TEST(SlamState, VariablesOwnTheirIndicesAndRemovalCompacts) {
  std::mt19937 rng(1);
  SlamState s = test::randomSlamState(3, rng);
  ASSERT_EQ(s.size(), 18);
  EXPECT_EQ(s.landmarkCount(), 3);
  EXPECT_EQ(s.find(VariableKey::landmark(101))->index, 12);
  EXPECT_EQ(s.find(VariableKey::landmark(102))->index, 15);
  const Eigen::MatrixXd P = s.covariance();
  const Eigen::VectorXd x = s.mean();

  ASSERT_TRUE(CovarianceHelper::marginalize(s, VariableKey::landmark(101)).ok());
  ASSERT_EQ(s.size(), 15);
  EXPECT_FALSE(s.has(VariableKey::landmark(101)));
  EXPECT_EQ(s.find(VariableKey::landmark(102))->index, 12);  // compacted
  // Every remaining block is the one it was before: marginalising a Gaussian drops rows.
  std::vector<int> keep;
  for (int i = 0; i < 18; ++i)
    if (i < 12 || i >= 15) keep.push_back(i);
  EXPECT_EQ(s.covariance(), Eigen::MatrixXd(P(keep, keep)));
  EXPECT_EQ(s.mean(), Eigen::VectorXd(x(keep)));
  EXPECT_FALSE(CovarianceHelper::marginalize(s, VariableKey::landmark(101)).ok());
  EXPECT_FALSE(CovarianceHelper::addVariable(s, VariableKey::landmark(100), Eigen::Vector3d::Zero(),
                                             Eigen::Matrix3d::Identity())
                   .ok());  // already present
}

TEST(CovarianceHelper, AugmentEqualsDenseFormula) {
  std::mt19937 rng(2);
  SlamState s = test::randomSlamState(2, rng);
  const int n = s.size();
  const Eigen::MatrixXd P = s.covariance();
  const Eigen::MatrixXd J_x = randomMatrix(3, n, rng);
  const Eigen::MatrixXd J_z = randomMatrix(3, 4, rng);
  const Eigen::MatrixXd R = randomCovariance(4, rng, 1.0);
  const Eigen::Vector3d y(1, 2, 3);
  ASSERT_TRUE(CovarianceHelper::augment(s, VariableKey::landmark(7), y, J_x, J_z, R).ok());
  ASSERT_EQ(s.size(), n + 3);
  Eigen::MatrixXd expected(n + 3, n + 3);
  expected << P, P * J_x.transpose(), J_x * P,
      J_x * P * J_x.transpose() + J_z * R * J_z.transpose();
  EXPECT_TRUE(s.covariance().isApprox(expected, 1e-12));
  EXPECT_EQ(s.covariance(), s.covariance().transpose());
  EXPECT_EQ(s.mean().tail<3>(), y);
  EXPECT_EQ(s.find(VariableKey::landmark(7))->index, n);
  EXPECT_FALSE(CovarianceHelper::augment(s, VariableKey::landmark(8), y, J_x, J_z, R).ok())
      << "J_x no longer matches the grown state";
}

TEST(CovarianceHelper, AugmentFromOneSourceEqualsDenseAugment) {
  std::mt19937 rng(3);
  SlamState a = test::randomSlamState(3, rng);
  SlamState b = a;
  const StateVariable& vehicle = *a.find(VariableKey::vehicle(0));
  const Eigen::MatrixXd J_v = randomMatrix(3, vehicle.size, rng);
  const Eigen::MatrixXd J_z = randomMatrix(3, 4, rng);
  const Eigen::Matrix4d R = Eigen::Matrix4d::Identity() * 2.0;
  Eigen::MatrixXd J_x = Eigen::MatrixXd::Zero(3, a.size());
  J_x.middleCols(vehicle.index, vehicle.size) = J_v;
  const Eigen::Vector3d y(4, 5, 6);
  ASSERT_TRUE(CovarianceHelper::augment(a, VariableKey::landmark(9), y, VariableKey::vehicle(0),
                                        J_v, J_z, R)
                  .ok());
  ASSERT_TRUE(CovarianceHelper::augment(b, VariableKey::landmark(9), y, J_x, J_z, R).ok());
  EXPECT_TRUE(a.covariance().isApprox(b.covariance(), 1e-12));
  EXPECT_FALSE(CovarianceHelper::augment(a, VariableKey::landmark(10), y, VariableKey::vehicle(5),
                                         J_v, J_z, R)
                   .ok());
}

TEST(CovarianceHelper, AugmentThenMarginaliseRestoresTheState) {
  std::mt19937 rng(31);
  SlamState s = test::randomSlamState(4, rng);
  const SlamState before = s;
  ASSERT_TRUE(CovarianceHelper::augment(s, VariableKey::landmark(1), Eigen::Vector3d(1, 1, 1),
                                        VariableKey::vehicle(0), randomMatrix(3, 9, rng),
                                        randomMatrix(3, 4, rng), Eigen::Matrix4d::Identity())
                  .ok());
  ASSERT_TRUE(CovarianceHelper::marginalize(s, VariableKey::landmark(1)).ok());
  EXPECT_EQ(s.covariance(), before.covariance());
  EXPECT_EQ(s.mean(), before.mean());
  // Removing the vehicle itself compacts every landmark.
  ASSERT_TRUE(CovarianceHelper::marginalize(s, VariableKey::vehicle(0)).ok());
  EXPECT_EQ(s.find(VariableKey::landmark(100))->index, 0);
  EXPECT_EQ(s.find(VariableKey::landmark(103))->index, 9);
  EXPECT_EQ(s.covariance(), before.covariance().bottomRightCorner(12, 12));
  ASSERT_TRUE(CovarianceHelper::scaleCovariance(s, 2.0).ok());
  EXPECT_EQ(s.covariance(), 2.0 * before.covariance().bottomRightCorner(12, 12));
  EXPECT_FALSE(CovarianceHelper::scaleCovariance(s, 0.0).ok());
}

TEST(CovarianceHelper, ScaleCovarianceOfOneVehiclesVariables) {
  std::mt19937 rng(9);
  const SlamState s = test::randomSlamState(3, rng);  // vehicle(0), landmarks 100..102
  const Eigen::MatrixXd P = s.covariance();
  // Every variable listed: exactly factor · P (covariance intersection of a single vehicle).
  std::vector<VariableKey> keys;
  for (const StateVariable& v : s.variables()) keys.push_back(v.key);
  SlamState all = s;
  ASSERT_TRUE(CovarianceHelper::scaleCovariance(all, keys, 2.5).ok());
  EXPECT_EQ(all.covariance(), 2.5 * P);
  // Some: P ← D P D with D = 2 (√4) on the vehicle and landmark 101, 1 elsewhere.
  SlamState some = s;
  ASSERT_TRUE(CovarianceHelper::scaleCovariance(
                  some, {VariableKey::vehicle(0), VariableKey::landmark(101)}, 4.0)
                  .ok());
  Eigen::VectorXd d = Eigen::VectorXd::Ones(s.size());
  d.head(9).setConstant(2.0);
  d.segment(12, 3).setConstant(2.0);
  EXPECT_LT((some.covariance() - d.asDiagonal() * P * d.asDiagonal()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(some.covariance().block(9, 9, 3, 3), P.block(9, 9, 3, 3));  // landmark 100
  EXPECT_GT(minEigenvalue(some.covariance()), -1e-12);
  EXPECT_FALSE(CovarianceHelper::scaleCovariance(some, {VariableKey::landmark(7)}, 2.0).ok());
  EXPECT_FALSE(CovarianceHelper::scaleCovariance(some, keys, 0.0).ok());
}

TEST(CovarianceHelper, MarginalCovarianceInRequestedOrder) {
  std::mt19937 rng(4);
  const SlamState s = test::randomSlamState(3, rng);
  const auto m = CovarianceHelper::marginalCovariance(
      s, {VariableKey::landmark(102), VariableKey::vehicle(0)});
  ASSERT_TRUE(m.ok());
  const Eigen::MatrixXd& P = s.covariance();
  EXPECT_EQ(m->block(0, 0, 3, 3), P.block(15, 15, 3, 3));
  EXPECT_EQ(m->block(3, 3, 9, 9), P.block(0, 0, 9, 9));
  EXPECT_EQ(m->block(0, 3, 3, 9), P.block(15, 0, 3, 9));
  EXPECT_FALSE(CovarianceHelper::marginalCovariance(s, {VariableKey::landmark(1)}).ok());
}

TEST(CovarianceHelper, PropagateEqualsDenseTransition) {
  std::mt19937 rng(5);
  SlamState s = test::randomSlamState(4, rng);
  const int n = s.size();
  const Eigen::MatrixXd P = s.covariance();
  const Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(9, 9) + randomMatrix(9, 9, rng, 0.1);
  const Eigen::MatrixXd Q = randomCovariance(9, rng, 0.05);
  UpdatePolicy policy;
  policy.process_noise_scale = 0.7;  // c_w² of an NH∞ policy
  const Eigen::VectorXd xv = randomMatrix(9, 1, rng);
  ASSERT_TRUE(CovarianceHelper::propagate(s, VariableKey::vehicle(0), xv, Phi, Q, policy).ok());
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
  F.topLeftCorner(9, 9) = Phi;
  Eigen::MatrixXd expected = F * P * F.transpose();
  expected.topLeftCorner(9, 9) += 0.7 * Q;
  EXPECT_TRUE(s.covariance().isApprox(expected, 1e-12));
  EXPECT_EQ(s.covariance(), s.covariance().transpose());
  EXPECT_EQ(s.mean().head(9), xv);
  EXPECT_EQ(s.covariance().bottomRightCorner(n - 9, n - 9), P.bottomRightCorner(n - 9, n - 9));
}

TEST(CovarianceHelper, JosephUpdateKeepsCovarianceSymmetricPositiveDefinite) {
  std::mt19937 rng(6);
  SlamState s = test::randomSlamState(24, rng);
  MeasurementBatch batch;
  for (int k = 0; k < 30; ++k) {
    const Eigen::MatrixXd P = s.covariance();
    // Very precise observations: the textbook P − K H P loses positive definiteness here.
    test::randomStereoBatch(s, 20, rng, &batch, 1e-3);
    ASSERT_TRUE(CovarianceHelper::update(s, batch, UpdatePolicy::ekf(), nullptr).ok());
    EXPECT_EQ(s.covariance(), s.covariance().transpose());
    EXPECT_GT(minEigenvalue(s.covariance()), 0.0) << "update " << k;
    // Never more uncertain than before (P⁺ ≤ P⁻).
    EXPECT_GT(minEigenvalue(P - s.covariance()), -1e-12);
  }
}

TEST(CovarianceHelper, SparseProductsEqualDense) {
  std::mt19937 rng(7);
  const SlamState s = test::randomSlamState(5, rng);
  MeasurementBatch batch;
  test::randomStereoBatch(s, 7, rng, &batch);
  const Eigen::MatrixXd H = batch.H();
  Eigen::MatrixXd PHt, HP;
  batch.multiplyByHt(s.covariance(), &PHt);
  batch.multiplyH(s.covariance(), &HP);
  EXPECT_TRUE(PHt.isApprox(s.covariance() * H.transpose(), 1e-12));
  EXPECT_TRUE(HP.isApprox(H * s.covariance(), 1e-12));
  // Setting a block twice overwrites it instead of counting it twice.
  MeasurementBatch twice = batch;
  twice.setJacobian(0, *s.find(VariableKey::vehicle(0)), H.block(0, 0, 4, 9));
  twice.multiplyByHt(s.covariance(), &PHt);
  EXPECT_TRUE(PHt.isApprox(s.covariance() * H.transpose(), 1e-12));
}

TEST(CovarianceHelper, ColumnTransformsOfTheJacobianKeepTheSparseProductsExact) {
  // H ← H T for the chart's transport (invariant_chart_transport.h): rotated columns, and
  // columns added into blocks an observation did not have (here another landmark's, which
  // only the blocks added by addColumns cover).
  std::mt19937 rng(8);
  const SlamState s = test::randomSlamState(5, rng);
  MeasurementBatch batch;
  test::randomStereoBatch(s, 7, rng, &batch);
  const Eigen::Matrix3d R = randomMatrix(3, 3, rng), C = randomMatrix(3, 3, rng);
  const int attitude = s.find(VariableKey::vehicle(0))->index + 6;
  const int a = s.variables()[1].index, b = s.variables()[2].index;  // two landmarks
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(s.size(), s.size());
  T.block<3, 3>(attitude, attitude) = R;
  T.block<3, 3>(a, b) = C;  // H(:, b) += H(:, a) C
  const Eigen::MatrixXd expected = batch.H() * T;
  batch.rotateColumns(attitude, R);
  batch.addColumns(b, a, C);
  EXPECT_TRUE(batch.H().isApprox(expected, 1e-12));
  Eigen::MatrixXd PHt, HP;
  batch.multiplyByHt(s.covariance(), &PHt);
  batch.multiplyH(s.covariance(), &HP);
  EXPECT_TRUE(PHt.isApprox(s.covariance() * expected.transpose(), 1e-12));
  EXPECT_TRUE(HP.isApprox(expected * s.covariance(), 1e-12));
}

/// Linear-Gaussian toy: 6-state constant-velocity "vehicle" and one static landmark, observed
/// through the relative position (touches both) and an absolute position fix. The helper's
/// EKF must equal a textbook dense Kalman filter.
TEST(CovarianceHelper, EkfEqualsReferenceKalmanFilterOnLinearToy) {
  std::mt19937 rng(8);
  std::normal_distribution<double> normal;
  const double dt = 0.1;
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(6, 6);
  Phi.topRightCorner(3, 3) = dt * Eigen::Matrix3d::Identity();
  const Eigen::MatrixXd Q = randomCovariance(6, rng, 0.05);
  Eigen::MatrixXd H_rel = Eigen::MatrixXd::Zero(3, 9), H_abs = Eigen::MatrixXd::Zero(3, 9);
  H_rel.leftCols(3) = -Eigen::Matrix3d::Identity();
  H_rel.rightCols(3) = Eigen::Matrix3d::Identity();
  H_abs.leftCols(3) = Eigen::Matrix3d::Identity();
  Eigen::MatrixXd H(6, 9);
  H << H_rel, H_abs;
  const Eigen::Matrix3d R_rel = 0.04 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d R_abs = 1.0 * Eigen::Matrix3d::Identity();
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(6, 6);
  R.topLeftCorner(3, 3) = R_rel;
  R.bottomRightCorner(3, 3) = R_abs;

  SlamState s;
  // A "vehicle" of 6 states: not the INS layout, so no angle wrapping applies.
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::vehicle(0), Eigen::VectorXd::Zero(6),
                                            Eigen::MatrixXd::Identity(6, 6))
                  .ok());
  ASSERT_TRUE(CovarianceHelper::addVariable(s, VariableKey::landmark(0), Eigen::Vector3d(5, 0, 0),
                                            4.0 * Eigen::Matrix3d::Identity())
                  .ok());
  Eigen::VectorXd x_ref = s.mean();
  Eigen::MatrixXd P_ref = s.covariance();
  Eigen::VectorXd x_true(9);
  x_true << 0.5, -0.2, 0.1, 1.0, 0.5, -0.2, 5.3, 0.4, -0.1;
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(9, 9);
  F.topLeftCorner(6, 6) = Phi;
  Eigen::MatrixXd Q_full = Eigen::MatrixXd::Zero(9, 9);
  Q_full.topLeftCorner(6, 6) = Q;
  MeasurementBatch batch;
  for (int k = 0; k < 50; ++k) {
    x_true = F * x_true;
    Eigen::VectorXd z = H * x_true;
    for (int i = 0; i < 6; ++i) z(i) += std::sqrt(R(i, i)) * normal(rng);
    // Reference: dense textbook Kalman filter.
    x_ref = F * x_ref;
    P_ref = F * P_ref * F.transpose() + Q_full;
    const Eigen::MatrixXd K = P_ref * H.transpose() * (H * P_ref * H.transpose() + R).inverse();
    x_ref += K * (z - H * x_ref);
    P_ref = (Eigen::MatrixXd::Identity(9, 9) - K * H) * P_ref;
    // Helper.
    ASSERT_TRUE(CovarianceHelper::propagate(s, VariableKey::vehicle(0), Phi * s.mean().head(6), Phi,
                                            Q, UpdatePolicy::ekf())
                    .ok());
    const Eigen::VectorXd r = z - H * s.mean();
    batch.reset(9, 6);
    const int g_rel = batch.addObservation(r.head(3), R_rel);
    batch.setJacobian(g_rel, *s.find(VariableKey::vehicle(0)), H_rel.leftCols(6));
    batch.setJacobian(g_rel, *s.find(VariableKey::landmark(0)), H_rel.rightCols(3));
    const int g_abs = batch.addObservation(r.tail(3), R_abs);
    batch.setJacobian(g_abs, 0, H_abs.leftCols(3));
    ASSERT_TRUE(CovarianceHelper::update(s, batch, UpdatePolicy::ekf(), nullptr).ok());
    ASSERT_TRUE(s.mean().isApprox(x_ref, 1e-9)) << "step " << k;
    ASSERT_TRUE(s.covariance().isApprox(P_ref, 1e-9)) << "step " << k;
  }
  EXPECT_LT((s.mean() - x_true).norm(), 1.0);
}

TEST(CovarianceHelper, GateRejectsOutliersAndAcceptsInliersAtTheRightRate) {
  std::mt19937 rng(9);
  SlamState s = test::randomSlamState(20, rng);
  const Eigen::LLT<Eigen::MatrixXd> P_llt(s.covariance());
  UpdatePolicy policy = UpdatePolicy::ekf(0.95);
  MeasurementBatch batch;
  FilterStatistics stats;
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 500; ++trial) {
    // Residuals drawn from the true innovation distribution: r = H e + v, e ~ N(0, P).
    test::randomStereoBatch(s, 20, rng, &batch);
    MeasurementBatch consistent;
    consistent.reset(s.size(), batch.rows());
    Eigen::VectorXd e(s.size());
    for (int i = 0; i < e.size(); ++i) e(i) = normal(rng);
    e = P_llt.matrixL() * e;
    const Eigen::VectorXd He = batch.H() * e;
    for (int g = 0; g < batch.groups(); ++g) {
      Eigen::Vector4d v;
      for (int i = 0; i < 4; ++i) v(i) = normal(rng);
      const int c =
          consistent.addObservation(He.segment<4>(4 * g) + v, Eigen::Matrix4d::Identity());
      consistent.setJacobian(c, 0, batch.H().block(4 * g, 0, 4, s.size()));
    }
    SlamState copy = s;
    UpdateReport report;
    ASSERT_TRUE(CovarianceHelper::update(copy, consistent, policy, &report).ok());
    stats.add(report);
  }
  const double accepted =
      static_cast<double>(stats.observations_accepted) /
      static_cast<double>(stats.observations_accepted + stats.observations_rejected);
  // Observations within one batch share e, so allow 6 binomial σ of 10000 draws.
  EXPECT_NEAR(accepted, 0.95, 6.0 * std::sqrt(0.95 * 0.05 / 10000.0));

  // One gross outlier among inliers: only it is rejected, and it does not move the state.
  test::randomStereoBatch(s, 5, rng, &batch, 0.0);
  MeasurementBatch with_outlier;
  with_outlier.reset(s.size(), 24);
  for (int g = 0; g < 6; ++g) {
    const Eigen::Vector4d r = g == 3 ? Eigen::Vector4d(80, -60, 80, -60) : Eigen::Vector4d::Zero();
    const int c = with_outlier.addObservation(r, Eigen::Matrix4d::Identity());
    with_outlier.setJacobian(c, 0, batch.H().block(4 * (g % 5), 0, 4, s.size()));
  }
  UpdateReport report;
  SlamState copy = s;
  ASSERT_TRUE(CovarianceHelper::update(copy, with_outlier, UpdatePolicy::ekf(0.999), &report).ok());
  EXPECT_EQ(report.observations_rejected, 1);
  EXPECT_EQ(report.observations_accepted, 5);
  EXPECT_TRUE(copy.mean().isApprox(s.mean(), 1e-12));  // inlier residuals are zero
  // Without the gate the outlier drags the state.
  copy = s;
  ASSERT_TRUE(CovarianceHelper::update(copy, with_outlier, UpdatePolicy::ekf(0.0), &report).ok());
  EXPECT_EQ(report.observations_accepted, 6);
  EXPECT_FALSE(copy.mean().isApprox(s.mean(), 1e-6));
}

TEST(CovarianceHelper, UpdateRejectsMismatchedBatch) {
  std::mt19937 rng(10);
  SlamState s = test::randomSlamState(2, rng);
  MeasurementBatch batch;
  batch.reset(s.size() + 3, 4);
  EXPECT_FALSE(CovarianceHelper::update(s, batch, UpdatePolicy::ekf(), nullptr).ok());
  EXPECT_EQ(batch.addObservation(Eigen::VectorXd::Zero(8), Eigen::MatrixXd::Identity(8, 8)), -1);
}

}  // namespace
}  // namespace cvslam
