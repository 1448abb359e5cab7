#pragma once
// Robust planar homography estimation (thesis §4.3.3.1, "Geometric Registration").
//
// Two views of a planar surface (the ground seen from a UAV, §4.3.3.1) are related by an
// 8-DOF homography x' ≅ H x (eq. 4.22/4.23). Each correspondence gives two linear equations
// in the entries of H (eq. 4.24): x'(h31 x + h32 y + h33) − h11 x − h12 y − h13 = 0 and
// y'(h31 x + h32 y + h33) − h21 x − h22 y − h23 = 0; N of them form A h = 0 (eq. 4.25),
// solved by the right singular vector of the smallest singular value. Points are first
// normalised (Hartley: centroid at 0, mean distance √2), without which the SVD solution is
// badly conditioned in pixel units.
//
// The thesis's feature matches contain outliers, hence "robust statistical methods for outlier
// rejection" (§4.3.3.1, [85]): RANSAC over minimal 4-point samples, then the inliers are
// refined by Levenberg–Marquardt on the transfer error |x' − π(H x)|² (the algebraic residual
// of eq. 4.25 is not a geometric distance) and re-classified once with the refined H.
//
// YAML (section `homography`):
//   ransac_threshold_px: 2.0   ransac_iterations: 2000   confidence: 0.999
//   refine_iterations: 20      min_inliers: 12           seed: 1

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::mosaic {

struct HomographyOptions {
  double ransac_threshold_px = 2.0;  ///< inlier if transfer error below this [px]
  int ransac_iterations = 2000;      ///< upper bound of RANSAC samples
  double confidence = 0.999;         ///< stop when an all-inlier sample was drawn this surely
  int refine_iterations = 20;        ///< Levenberg–Marquardt iterations on the inliers
  int min_inliers = 12;              ///< fewer inliers: registration fails
  uint64_t seed = 1;                 ///< RANSAC sample stream (deterministic)

  Status load(const ConfigNode& node);
};

struct HomographyEstimate {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();  ///< dst ≅ H src, H(2,2) = 1
  std::vector<bool> inliers;                        ///< per correspondence
  int inlier_count = 0;
  double rms_px = 0.0;  ///< RMS transfer error of the inliers [px]
};

/// Applies H to a point (inhomogeneous).
Eigen::Vector2d applyHomography(const Eigen::Matrix3d& H, const Eigen::Vector2d& x);

/// Direct linear transform (eq. 4.24–4.25) on all given pairs (≥ 4), with normalisation.
Expected<Eigen::Matrix3d> homographyDlt(const std::vector<Eigen::Vector2d>& src,
                                        const std::vector<Eigen::Vector2d>& dst);

/// Levenberg–Marquardt refinement of H on the transfer error of the given pairs.
Eigen::Matrix3d refineHomography(const Eigen::Matrix3d& H, const std::vector<Eigen::Vector2d>& src,
                                 const std::vector<Eigen::Vector2d>& dst, int iterations);

/// RANSAC + DLT + refinement. Fails with fewer than min_inliers inliers.
Expected<HomographyEstimate> estimateHomography(const std::vector<Eigen::Vector2d>& src,
                                                const std::vector<Eigen::Vector2d>& dst,
                                                const HomographyOptions& options);

}  // namespace cvslam::mosaic
