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
// The Hessians are central differences of the analytic Jacobian (StereoCamera::project).

#include <Eigen/Core>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/ins/estimated_pose.h"

namespace cvslam {

/// ΔR (4×4, positive semi-definite) of observing p_LinN from `pose` when the joint covariance
/// of (pose [p, v, attitude in the pose's coordinates], landmark) is P (12×12).
Eigen::Matrix4d stereoSecondOrderNoise(const StereoCamera& camera, const EstimatedPose& pose,
                                       const Eigen::Vector3d& p_LinN,
                                       const Eigen::Matrix<double, 12, 12>& P);

}  // namespace cvslam
