// The second-order term of the stereo prediction (slam/stereo_second_order_noise.h): its
// Hessians agree with second differences of the projection itself, it is positive
// semi-definite, and it is the covariance of what the linear model leaves out of h(x) over
// samples of x when the landmark's depth is uncertain (a landmark just triangulated); the
// mean term is the mean of what it leaves out — in the right-invariant chart over the
// invariant error, where a turn of vehicle and landmark together is no uncertainty of h.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <random>

#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/stereo_second_order_noise.h"

namespace cvslam {
namespace {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// h at the pose and landmark moved by d (Euler attitude: the angles move; error state:
/// R̂ Exp(δθ)).
Eigen::Vector4d projectMoved(const StereoCamera& camera, const EstimatedPose& pose,
                             const Eigen::Vector3d& p, const Vector12d& d) {
  EstimatedPose moved = pose;
  moved.p_BinN += d.segment<3>(vehicle::kPosition);
  moved.v_B += d.segment<3>(vehicle::kVelocity);
  if (pose.attitude == vehicle::Attitude::kEuler) {
    moved.euler += d.segment<3>(vehicle::kAttitude);
    moved.R_BtoN = rotationBodyToNav(moved.euler);
  } else {
    moved.R_BtoN = pose.R_BtoN * so3::exp(Eigen::Vector3d(d.segment<3>(vehicle::kAttitude)));
  }
  return camera.project(moved, p + d.tail<3>());
}

class StereoSecondOrderNoiseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    StereoCamera::Vector9d x;
    x << 2.0, -1.0, -10.0, 3.0, 0.1, 0.0, 0.05, -0.03, 0.8;
    pose_ = EstimatedPose::fromEuler(x);
    // A ground point 10 m below, off the optical axis, whose depth is known to ≈ 0.6 m (its
    // first stereo triangulation at 11 px of disparity), the vehicle to a few centimetres.
    p_ = x.head<3>() + Eigen::Vector3d(2.5, -1.5, 10.0);
    Eigen::Matrix<double, 12, 12> L = Eigen::Matrix<double, 12, 12>::Zero();
    L.diagonal() << 0.05, 0.05, 0.05, 0.02, 0.02, 0.02, 0.004, 0.004, 0.01, 0.1, 0.1, 0.6;
    L(11, 2) = 0.04;  // the landmark shares some of the vehicle's error
    L(9, 8) = 0.02;
    P_ = L * L.transpose();
  }
  StereoCamera camera_;
  EstimatedPose pose_;
  Eigen::Vector3d p_;
  Matrix12d P_;
};

TEST_F(StereoSecondOrderNoiseTest, HessiansAgreeWithSecondDifferencesOfTheProjection) {
  // ∇²h_i by second differences of h (not of its Jacobian), then ½ tr(∇²h_i P ∇²h_j P).
  constexpr double e = 1e-4;
  std::array<Matrix12d, 4> hessian;
  for (int a = 0; a < 12; ++a) {
    for (int b = 0; b < 12; ++b) {
      Vector12d da = Vector12d::Zero(), db = Vector12d::Zero();
      da(a) = e;
      db(b) = e;
      const Eigen::Vector4d h2 =
          (projectMoved(camera_, pose_, p_, da + db) - projectMoved(camera_, pose_, p_, da - db) -
           projectMoved(camera_, pose_, p_, db - da) + projectMoved(camera_, pose_, p_, -da - db)) /
          (4.0 * e * e);
      for (int i = 0; i < 4; ++i) hessian[static_cast<std::size_t>(i)](a, b) = h2(i);
    }
  }
  Eigen::Matrix4d expected;
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 4; ++j)
      expected(static_cast<int>(i), static_cast<int>(j)) =
          0.5 * (hessian[i] * P_ * hessian[j] * P_).trace();
  const Eigen::Matrix4d delta = stereoSecondOrderTerms(camera_, pose_, p_, P_).noise;
  std::cout << "ΔR =\n" << delta << "\n";
  EXPECT_LT((delta - expected).norm(), 1e-4 * expected.norm()) << expected;
  EXPECT_GT(delta(0, 0), 0.05) << "the term should matter here: R is 0.25 px²";
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(delta).eigenvalues().minCoeff(), -1e-12);
}

/// r = h(x) − h(x̂) − H (x − x̂) for x ~ N(x̂, P): what the EKF's linear model leaves out. Its
/// covariance is ΔR to second order (the odd moments of a Gaussian vanish), its mean the mean
/// term.
void expectTermsMatchSamples(const StereoCamera& camera, const EstimatedPose& pose,
                             const Eigen::Vector3d& p, const Matrix12d& P) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  const Matrix12d L = Eigen::LLT<Matrix12d>(P).matrixL();
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  const Eigen::Vector4d z0 = camera.project(pose, p, &dz_dxv, &dz_dpL);
  Eigen::Matrix<double, 4, 12> H;
  H << dz_dxv, dz_dpL;
  constexpr int kSamples = 100000;
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  Eigen::Matrix4d sum2 = Eigen::Matrix4d::Zero();
  for (int s = 0; s < kSamples; ++s) {
    Vector12d w;
    for (int k = 0; k < 12; ++k) w(k) = n01(rng);
    const Vector12d dx = L * w;
    const Eigen::Vector4d r = projectMoved(camera, pose, p, dx) - z0 - H * dx;
    sum += r;
    sum2 += r * r.transpose();
  }
  const Eigen::Vector4d mean = sum / kSamples;
  const Eigen::Matrix4d sampled = sum2 / kSamples - mean * mean.transpose();
  const StereoSecondOrderTerms terms = stereoSecondOrderTerms(camera, pose, p, P);
  const Eigen::Matrix4d& delta = terms.noise;
  std::cout << "sampled cov(r) =\n" << sampled << "\nΔR =\n" << delta << "\n";
  // Sampling error ≈ √(2/N) ≈ 0.5 %; the rest (≈ 6 % here) is of higher order in the depth's
  // relative σ (the series of 1/Z), which is 6 % for this landmark.
  EXPECT_LT((delta - sampled).norm(), 0.1 * sampled.norm());
  // E[r] is the mean term ½ tr(∇²h_i P): h(x̂) under-predicts the disparity (1/Z is convex).
  // Sampling error of the mean: √(ΔR_ii / N) ≈ 0.002 px.
  std::cout << "sampled E[r] = " << mean.transpose() << "\nmean term = " << terms.mean.transpose()
            << "\n";
  const double disparity_bias = terms.mean(0) - terms.mean(2);
  EXPECT_GT(disparity_bias, 0.03) << "the term should matter here";
  EXPECT_NEAR(mean(0) - mean(2), disparity_bias, 0.1 * disparity_bias);
  EXPECT_LT((terms.mean - mean).norm(), 0.1 * terms.mean.norm());
}

TEST_F(StereoSecondOrderNoiseTest, IsTheCovarianceOfTheLinearisationErrorOverSamples) {
  expectTermsMatchSamples(camera_, pose_, p_, P_);
}

TEST_F(StereoSecondOrderNoiseTest, MatchesTheSamplesWithTheRotationErrorStateToo) {
  // The agents' attitude (R̂ Exp(δθ)): the Hessian of the Jacobian carries an antisymmetric part
  // there, which the quadratic forms must not see. Tilted 20° as in a turn.
  EstimatedPose tilted;
  tilted.p_BinN = pose_.p_BinN;
  tilted.v_B = pose_.v_B;
  tilted.R_BtoN = rotationBodyToNav(Eigen::Vector3d(0.35, -0.1, 0.8));
  Matrix12d P = P_;
  P.block<3, 3>(vehicle::kAttitude, vehicle::kAttitude) *= 4.0;  // 1.6° tilt σ, 4° heading σ
  expectTermsMatchSamples(camera_, tilted, p_, P);
}

TEST_F(StereoSecondOrderNoiseTest, InTheInvariantChartTheMeanIsOverTheInvariantError) {
  // A vehicle 150 m from the origin whose heading is known to 2°, the landmark mapped from it:
  // the filter's Gaussian is over ξ = (ξθ, ·, δp + p̂ × ξθ, δl + l̂ × ξθ) (slam_state.h), with
  // x = Exp(ξ) x̂: R = Exp(ξθ) R̂, p = Exp(ξθ) p̂ + J_l(ξθ) ξp, l likewise. Its covariance in the
  // additive errors δ, which the filter stores, is A⁻¹ P_ξ A⁻ᵀ.
  EstimatedPose far;
  far.p_BinN = Eigen::Vector3d(150.0, 20.0, -10.0);
  far.R_BtoN = rotationBodyToNav(Eigen::Vector3d(0.05, -0.03, 0.8));
  const Eigen::Vector3d l = far.p_BinN + Eigen::Vector3d(2.5, -1.5, 10.0);
  const Eigen::Matrix3d M = vehicle_model::navRotationPerAttitude(far);
  Matrix12d A = Matrix12d::Identity();  // δ → ξ
  A.block<3, 3>(vehicle::kAttitude, vehicle::kAttitude) = M;
  A.block<3, 3>(vehicle::kPosition, vehicle::kAttitude) = so3::skew<double>(far.p_BinN) * M;
  A.block<3, 3>(9, vehicle::kAttitude) = so3::skew<double>(l) * M;
  Matrix12d L_xi = Eigen::LLT<Matrix12d>(P_).matrixL();
  L_xi(vehicle::kAttitude + 2, vehicle::kAttitude + 2) = 2.0 * M_PI / 180.0;  // heading σ 2°
  const Matrix12d P_xi = L_xi * L_xi.transpose();
  const Matrix12d A_inv = A.inverse();
  const Matrix12d P_delta = A_inv * P_xi * A_inv.transpose();

  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  const Eigen::Vector4d z0 = camera_.project(far, l, &dz_dxv, &dz_dpL);
  Eigen::Matrix<double, 4, 12> H;
  H << dz_dxv, dz_dpL;
  std::mt19937 rng(11);
  std::normal_distribution<double> n01;
  constexpr int kSamples = 100000;
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (int s = 0; s < kSamples; ++s) {
    Vector12d w;
    for (int k = 0; k < 12; ++k) w(k) = n01(rng);
    const Vector12d xi = L_xi * w;
    const Eigen::Vector3d th = xi.segment<3>(vehicle::kAttitude);
    const Eigen::Matrix3d turn = so3::exp(th);
    const Eigen::Matrix3d J_l = so3::rightJacobian(Eigen::Vector3d(-th));
    EstimatedPose x = far;
    x.R_BtoN = turn * far.R_BtoN;
    x.p_BinN = turn * far.p_BinN + J_l * xi.segment<3>(vehicle::kPosition);
    const Eigen::Vector3d l_s = turn * l + J_l * xi.tail<3>();
    // Minus the linear model in δ = A⁻¹ ξ (zero mean): only the sampling noise of the rest.
    sum += camera_.project(x, l_s) - z0 - H * (A_inv * xi);
  }
  const Eigen::Vector4d sampled = sum / kSamples;
  const Eigen::Vector4d invariant =
      stereoSecondOrderTerms(camera_, far, l, P_delta, ErrorChart::kRightInvariant).mean;
  const Eigen::Vector4d additive = stereoSecondOrderTerms(camera_, far, l, P_delta).mean;
  std::cout << "sampled E[r] = " << sampled.transpose()
            << "\ninvariant mean term = " << invariant.transpose()
            << "\nadditive mean term = " << additive.transpose() << "\n";
  EXPECT_LT((invariant - sampled).norm(), 0.1 * sampled.norm() + 0.005);
  // The additive chart reads the heading's straight-line variance as curvature: far off.
  EXPECT_GT((additive - sampled).norm(), 5.0 * (invariant - sampled).norm());
  // The disparity's mean is the depth's curvature in both.
  EXPECT_NEAR(invariant(0) - invariant(2), sampled(0) - sampled(2),
              0.1 * (sampled(0) - sampled(2)) + 0.002);
}

}  // namespace
}  // namespace cvslam
