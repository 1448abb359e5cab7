#pragma once
// Geometric verification of a place match between two agents: the 4-dof frame relation
// (frame_relation.h) from matched metric landmarks, each agent's in its own frame, robust to
// wrong matches. As the peers do it with gravity known (D2SLAM's 4-dof check, Kimera-Multi's
// 3-point RANSAC, COVINS' ≥ 20 inliers):
//  1. RANSAC over minimal samples of two correspondences: ψ from the horizontal direction
//     between the two points in each frame, t from their mean; the inliers of a hypothesis
//     are the correspondences whose residual r = p_A − (R_z(ψ) p_B + t) passes a χ²₃ gate on
//     its own covariance S = C_A + R C_B Rᵀ (a far, poorly triangulated landmark may be off
//     by more metres than a near one).
//  2. Generalised least squares on the best hypothesis' inliers with their JOINT covariances
//     (a filter's landmarks are correlated through its vehicle; treating them as independent
//     would make the relation look more certain than it is): Gauss–Newton on
//     rᵀ S⁻¹ r, re-gating every correspondence after each solve until the set settles.
//  3. The relation's covariance P = (Jᵀ S⁻¹ J)⁻¹ from the inliers' covariances, not a fixed
//     number; a verification with too few inliers, or inliers bunched in one spot, is refused.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/merge/frame_relation.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::merge {

/// Correspondences: a[k] (frame A) and b[k] (frame B) are the same landmark. cov_a and cov_b
/// are the 3n×3n joint covariances of the stacked points (block-diagonal when independent;
/// blockDiagonal() builds one).
struct AlignmentPoints {
  std::vector<Eigen::Vector3d> a;
  std::vector<Eigen::Vector3d> b;
  Eigen::MatrixXd cov_a;
  Eigen::MatrixXd cov_b;
};

/// The 3n×3n block-diagonal matrix of n 3×3 blocks.
Eigen::MatrixXd blockDiagonal(const std::vector<Eigen::Matrix3d>& blocks);

struct FourDofAlignerOptions {
  int ransac_iterations = 300;       ///< minimal samples tried
  double inlier_probability = 0.99;  ///< χ²₃ gate of one correspondence
  int min_inliers = 12;              ///< fewer: the verification fails
  double min_pair_separation = 0.5;  ///< horizontal distance of a minimal sample's points [m]
  double min_inlier_spread = 1.0;    ///< rms horizontal distance of the inliers from their mean [m]
  int refine_iterations = 10;        ///< Gauss–Newton steps per inlier set
  int regate_rounds = 3;             ///< re-gating rounds after the first solve
  uint64_t seed = 1;                 ///< RANSAC's sampling seed (deterministic runs)

  Status load(const ConfigNode& node);
};

struct FourDofAlignment {
  FrameRelation relation;    ///< B → A with its covariance
  std::vector<int> inliers;  ///< indices into the correspondences
  double inlier_nis = 0.0;  ///< rᵀ S⁻¹ r over the inliers, divided by 3m − 4 (≈ 1 if consistent)
  int hypothesis_inliers = 0;  ///< inliers of the best minimal sample, before refinement
};

class FourDofAligner {
 public:
  explicit FourDofAligner(const FourDofAlignerOptions& options = {});

  /// The relation of B in A; an error (with the reason) when the points are malformed or the
  /// verification does not pass.
  Expected<FourDofAlignment> align(const AlignmentPoints& points) const;

 private:
  FourDofAlignerOptions o_;
  double gate_ = 0.0;  // χ²₃ quantile of inlier_probability
};

}  // namespace cvslam::merge
