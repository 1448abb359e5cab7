// Cooperation geometry and covariance intersection (thesis §6.6.2, §6.6.4): the exact
// ellipsoid intersection test against a brute-force sampler, and CI consistency by Monte Carlo
// for every weight method and any true cross-correlation.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <random>

#include "cvslam/coop/feature_ellipsoid.h"
#include "cvslam/filter/covariance_intersection.h"

namespace cvslam::coop {
namespace {

/// Brute force: does a point of ellipsoid 1 (sampled on a dense grid of its bounding box)
/// fall inside ellipsoid 2? Returns the smallest normalised radius² of E2 found over E1.
double bruteForceMinRadius(const Eigen::Vector3d& m1, const Eigen::Vector3d& a1,
                           const Eigen::Vector3d& m2, const Eigen::Vector3d& a2) {
  constexpr int kSteps = 60;
  double best = 1e300;
  for (int i = 0; i <= kSteps; ++i)
    for (int j = 0; j <= kSteps; ++j)
      for (int k = 0; k <= kSteps; ++k) {
        const Eigen::Vector3d u(2.0 * i / kSteps - 1, 2.0 * j / kSteps - 1, 2.0 * k / kSteps - 1);
        if (u.squaredNorm() > 1.0) continue;
        const Eigen::Vector3d x = m1 + u.cwiseProduct(a1);
        best = std::min(best, (x - m2).cwiseQuotient(a2).squaredNorm());
      }
  return best;
}

TEST(FeatureEllipsoid, MeanAndStdOfPoints) {
  const FeatureEllipsoid e = ellipsoidOf({{0, 0, 0}, {2, 0, 4}, {4, 0, 8}});
  EXPECT_EQ(e.count, 3);
  EXPECT_NEAR(e.mean.x(), 2.0, 1e-12);
  EXPECT_NEAR(e.std.x(), std::sqrt(8.0 / 3.0), 1e-12);
  EXPECT_NEAR(e.std.y(), 0.0, 1e-12);
  EXPECT_NEAR(e.std.z(), 2.0 * std::sqrt(8.0 / 3.0), 1e-12);
  EXPECT_FALSE(ellipsoidOf({}).valid());
}

TEST(FeatureEllipsoid, ExactTestAgreesWithBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> axis(0.3, 3.0), pos(-6.0, 6.0);
  int agree_far = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Eigen::Vector3d m1(pos(rng), pos(rng), pos(rng)), m2(pos(rng), pos(rng), pos(rng));
    const Eigen::Vector3d a1(axis(rng), axis(rng), axis(rng)), a2(axis(rng), axis(rng), axis(rng));
    const bool exact = minOverlapMeasure(m1, a1, m2, a2) >= 0.0;
    const double r2 = bruteForceMinRadius(m1, a1, m2, a2);
    // The grid resolves the boundary only to a few %: compare away from touching.
    if (r2 < 0.9) {
      EXPECT_TRUE(exact) << "trial " << trial;
      ++agree_far;
    } else if (r2 > 1.1) {
      EXPECT_FALSE(exact) << "trial " << trial;
      ++agree_far;
    }
  }
  EXPECT_GT(agree_far, 40);
}

TEST(FeatureEllipsoid, TouchingSeparatedContained) {
  const Eigen::Vector3d a1(2, 1, 1), a2(1, 3, 1);
  // Along x, surfaces touch when the centre distance is a1.x + a2.x = 3.
  EXPECT_NEAR(minOverlapMeasure({0, 0, 0}, a1, {3, 0, 0}, a2), 0.0, 1e-6);
  EXPECT_TRUE(minOverlapMeasure({0, 0, 0}, a1, {2.99, 0, 0}, a2) >= 0.0);
  EXPECT_FALSE(minOverlapMeasure({0, 0, 0}, a1, {3.01, 0, 0}, a2) >= 0.0);
  // Diagonal separation where bounding spheres (radii 2 and 3) would overlap: not touching.
  EXPECT_TRUE(minOverlapMeasure({0, 0, 0}, {2, 0.2, 0.2}, {1.5, 1.5, 0}, {0.2, 3, 0.2}) >= 0.0);
  EXPECT_FALSE(minOverlapMeasure({0, 0, 0}, {2, 0.2, 0.2}, {1.2, 1.5, 0}, {0.2, 0.2, 3}) >= 0.0);
  // Contained: the small one inside the large one.
  EXPECT_TRUE(minOverlapMeasure({0, 0, 0}, {5, 5, 5}, {1, 1, 1}, {0.1, 0.1, 0.1}) >= 0.0);
  // Zero std (one feature each): the floor gives them a volume.
  FeatureEllipsoid p1, p2;
  p1.count = p2.count = 1;
  p2.mean = {1.5, 0, 0};
  EXPECT_TRUE(ellipsoidsIntersect(p1, p2, 2.0, 1.0));
  EXPECT_FALSE(ellipsoidsIntersect(p1, p2, 2.0, 0.5));
}

/// Random SPD 3×3 matrix with eigenvalues in [lo, hi].
Eigen::Matrix3d randomCovariance(std::mt19937& rng, double lo, double hi) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(lo, hi);
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = n(rng);
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr(A);
  const Eigen::Matrix3d Q = qr.householderQ();
  return Q * Eigen::Vector3d(u(rng), u(rng), u(rng)).asDiagonal() * Q.transpose();
}

TEST(CovarianceIntersection, WeightsFollowTheirDefinitions) {
  const Eigen::Matrix3d P1 = Eigen::Matrix3d::Identity(), P2 = 3.0 * Eigen::Matrix3d::Identity();
  EXPECT_NEAR(fastCiOmega(P1, P2), 0.75, 1e-12);                       // eq. 6.4
  EXPECT_NEAR(adaptiveCiOmega(P1, P2, 1.0, 9.0), 18.0 / 22.0, 1e-12);  // eq. 6.5
  // Scaled identities: the trace-optimal ω puts all weight on the better estimate.
  EXPECT_NEAR(optimalCiOmega(P1, P2, false), 1.0, 1e-9);
  // Crossed ellipses: the optimum is interior and beats both ends.
  Eigen::Matrix2d A = Eigen::Vector2d(1.0, 10.0).asDiagonal(),
                  B = Eigen::Vector2d(10.0, 1.0).asDiagonal();
  const double w = optimalCiOmega(A, B, false);
  EXPECT_NEAR(w, 0.5, 1e-5);
  auto f = fuseCovarianceIntersection(Eigen::Vector2d::Zero(), A, Eigen::Vector2d::Zero(), B, w);
  ASSERT_TRUE(f.ok());
  EXPECT_LT(f->P.trace(), A.trace());
  EXPECT_NEAR(optimalCiOmega(A, B, true), 0.5, 1e-5);
  EXPECT_EQ(parseCiMethod("optimal_determinant").value(), CiMethod::kOptimalDeterminant);
  EXPECT_FALSE(parseCiMethod("best").ok());
  EXPECT_FALSE(
      fuseCovarianceIntersection(Eigen::Vector3d::Zero(), P1, Eigen::Vector3d::Zero(), -P2, 0.5)
          .ok());
}

// The closed form for the vehicle block equals the information-form joint CI update.
TEST(CovarianceIntersection, JointVehicleTraceMatchesInformationForm) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::MatrixXd A(9, 9);
  for (int i = 0; i < 81; ++i) A(i / 9, i % 9) = n01(rng);
  const Eigen::MatrixXd P = A * A.transpose() + 0.1 * Eigen::MatrixXd::Identity(9, 9);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6, 9);  // two landmarks after a 3-D position
  H.block(0, 3, 6, 6).setIdentity();
  const Eigen::MatrixXd R = 0.5 * Eigen::MatrixXd::Identity(6, 6);
  for (double w : {0.1, 0.5, 0.9}) {
    const Eigen::MatrixXd info = w * P.inverse() + (1 - w) * H.transpose() * R.inverse() * H;
    const double expected = info.inverse().topLeftCorner(3, 3).trace();
    EXPECT_NEAR(jointCiVehiclePositionTrace(P.topLeftCorner(3, 3), P.block(0, 3, 3, 6),
                                            P.bottomRightCorner(6, 6), R, w),
                expected, 1e-9 * expected);
  }
  EXPECT_EQ(jointCiVehiclePositionTrace(P.topLeftCorner(3, 3), P.block(0, 3, 3, 6),
                                        P.bottomRightCorner(6, 6), R, 1.0),
            P.topLeftCorner(3, 3).trace());
  const double w = optimalVehicleCiOmega(P.topLeftCorner(3, 3), P.block(0, 3, 3, 6),
                                         P.bottomRightCorner(6, 6), R, 0.05);
  const double best = jointCiVehiclePositionTrace(P.topLeftCorner(3, 3), P.block(0, 3, 3, 6),
                                                  P.bottomRightCorner(6, 6), R, w);
  for (double v = 0.05; v <= 1.0; v += 0.05)
    EXPECT_LE(best, jointCiVehiclePositionTrace(P.topLeftCorner(3, 3), P.block(0, 3, 3, 6),
                                                P.bottomRightCorner(6, 6), R, v) +
                        1e-9);
}

// For random P1, P2 and a true joint error covariance with those marginals and random
// cross-correlation (including ±fully correlated), the CI estimate's empirical error
// covariance must not exceed the fused P (PSD sense, within Monte-Carlo tolerance), for every
// weight method.
TEST(CovarianceIntersection, ConsistentForAnyCorrelationMonteCarlo) {
  std::mt19937 rng(2024);
  std::normal_distribution<double> n01(0.0, 1.0);
  constexpr int kSamples = 20000;
  constexpr double kTolerance = 0.06;  // relative Monte-Carlo error of a variance at 20000
  const CiMethod methods[] = {CiMethod::kAdaptive, CiMethod::kFast, CiMethod::kOptimalTrace,
                              CiMethod::kOptimalDeterminant, CiMethod::kOptimalVehicle};
  for (int trial = 0; trial < 12; ++trial) {
    const Eigen::Matrix3d P1 = randomCovariance(rng, 0.2, 4.0),
                          P2 = randomCovariance(rng, 0.2, 4.0);
    const Eigen::Matrix3d L1 = P1.llt().matrixL(), L2 = P2.llt().matrixL();
    // e1 = L1 a, e2 = L2 (ρ a + sqrt(1−ρ²) b): cross-covariance ρ L1 L2ᵀ; ρ = ±1 is full
    // correlation. Trials 0..2 use ρ = 1, −1, 0.
    const double rho = trial == 0   ? 1.0
                       : trial == 1 ? -1.0
                       : trial == 2 ? 0.0
                                    : std::uniform_real_distribution<double>(-1, 1)(rng);
    for (CiMethod m : methods) {
      const double w = ciOmega(m, P1, P2, 0.5, 2.0);
      auto f =
          fuseCovarianceIntersection(Eigen::Vector3d::Zero(), P1, Eigen::Vector3d::Zero(), P2, w);
      ASSERT_TRUE(f.ok());
      const Eigen::Matrix3d K1 = w * f->P * P1.inverse(), K2 = (1 - w) * f->P * P2.inverse();
      Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
      for (int k = 0; k < kSamples; ++k) {
        const Eigen::Vector3d a(n01(rng), n01(rng), n01(rng)), b(n01(rng), n01(rng), n01(rng));
        const Eigen::Vector3d e1 = L1 * a;
        const Eigen::Vector3d e2 = L2 * (rho * a + std::sqrt(std::max(0.0, 1 - rho * rho)) * b);
        const Eigen::Vector3d e = K1 * e1 + K2 * e2;
        S += e * e.transpose();
      }
      S /= kSamples;
      // P − S ⪰ −tol·P  ⇔  eigenvalues of P^{-1/2} S P^{-1/2} ≤ 1 + tol.
      const Eigen::Matrix3d Lp = f->P.llt().matrixL();
      const Eigen::Matrix3d N = Lp.inverse() * S * Lp.inverse().transpose();
      const double lmax =
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(N).eigenvalues().maxCoeff();
      EXPECT_LE(lmax, 1.0 + kTolerance)
          << "trial " << trial << " method " << ciMethodName(m) << " rho " << rho;
    }
  }
}

}  // namespace
}  // namespace cvslam::coop
