#pragma once
// The second-order term of a stereo observation's prediction (the Gaussian second-order
// filter: Bar-Shalom, Li & Kirubarajan, "Estimation with applications to tracking", §10.3;
// Jazwinski 1970): with x = (vehicle pose, landmark) ~ N(x̂, P) and h the stereo projection,
//   cov(h(x)) ≈ H P Hᵀ + ΔR,   ΔR_ij = ½ tr(∇²h_i P ∇²h_j P),
// where the EKF keeps only H P Hᵀ. A landmark triangulated from a few pixels of disparity has a
// depth σ of several per cent, and the curvature of u = f X / Z in Z then makes ΔR as large as
// the pixel noise itself: the EKF's first updates of every new landmark count information the
// observation does not carry (docs/results/ideal_ekf.md). Adding ΔR to R is the filter's
// honest account of its own linearisation error; it vanishes as the landmark converges.
// The same Hessians give the prediction's mean, E[h(x)] ≈ h(x̂) + ½ tr(∇²h_i P) (the filter's
// second-order mean; slam.second_order_mean): the EKF's h(x̂) is biased by the curvature of
// 1/Z, and that bias, always of one sign, shortens every landmark's depth a little and with it
// the distance the vehicle is found to have flown (docs/filter.md "The second-order mean").
// The Hessians are central differences of the analytic Jacobian (StereoCamera::project), taken
// in the 6 coordinates h depends on (the attitude and l − p; not the velocity): 12 Jacobian
// evaluations and 6×6 products per observation.

#include <Eigen/Core>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/ins/estimated_pose.h"

namespace cvslam {

/// The two second-order terms of one stereo prediction.
struct StereoSecondOrderTerms {
  Eigen::Vector4d mean;   ///< ½ tr(∇²h_i P): E[h(x)] − h(x̂) to second order [px]
  Eigen::Matrix4d noise;  ///< ΔR (positive semi-definite) [px²]
};

/// The terms of observing p_LinN from `pose` when the joint covariance of the additive errors
/// of (pose [p, v, attitude in the pose's coordinates], landmark) is P (12×12). `chart` is
/// what the filter's Gaussian is over (slam_state.h): with kRightInvariant the mean term is
/// taken over the invariant error ξ (x = Exp(ξ) x̂), where a rotation of vehicle and landmark
/// together does not move the prediction; ΔR stays the additive one.
StereoSecondOrderTerms stereoSecondOrderTerms(const StereoCamera& camera, const EstimatedPose& pose,
                                              const Eigen::Vector3d& p_LinN,
                                              const Eigen::Matrix<double, 12, 12>& P,
                                              ErrorChart chart = ErrorChart::kAdditive);

}  // namespace cvslam
