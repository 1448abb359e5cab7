#pragma once
// Global adjustment of the frames of a mosaic (thesis §4.3.3.2 registers each image to the
// mosaic; with many images, chaining these registrations drifts, so here all pairwise
// registrations are reconciled at once, with the estimated poses as the prior).
//
// Each frame k is placed by its pose prior G_k (image → mosaic pixel, mosaic_builder.h) and
// a homography correction C_k of the mosaic plane, expressed around the centre c_k of its
// prior footprint in units of its size s_k (for conditioning): p = c + s·π((I + Δ_k) q),
// q = [(g − c)/s; 1], g = G_k(x). Residuals:
//  - a link (matched, RANSAC-inlier feature pair x_i ↔ x_j between two frames): p_i − p_j,
//    weight 1/σ_match: the same ground point must land on the same mosaic pixel;
//  - smoothness: the corrections of consecutive frames of one UAV differ by little (the
//    estimate's drift is slow), weight 1/σ_smooth;
//  - the prior (the pose estimate holds the mosaic in the team frame, and places frames that
//    have no link): the shift of the footprint centre, weight 1/σ_shift, and the move of the
//    corners relative to it (rotation, scale), weight 1/σ_shape.
// Solved by Gauss–Newton on the sparse normal equations (8 unknowns per frame). A full
// homography, not an affine map, because the terrain under a frame is a tilted plane
// rather than the prior's level plane D = ground_down: a slope of 0.1 changes the scale by
// ~3 % across a 10 m-high footprint, i.e. several pixels, which only the projective terms
// absorb.
//
// YAML (section `mosaic.adjustment`):
//   model: similarity   sigma_match_px: 2.0   sigma_cross_px: 2.0   sigma_smooth_px: 0.03
//   sigma_shift_px: 20.0   sigma_shape_px: 10.0
//   iterations: 5

#include <Eigen/Core>

#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::mosaic {

/// Degrees of freedom of the correction of a frame. `similarity` (shift, rotation, scale)
/// is what errors of the estimated pose do to a near-nadir view of a plane; `affine` and
/// `homography` also absorb ground tilt, but leave low-frequency distortions of a long
/// strip of frames weakly determined by the links (they drift as the chain grows).
enum class CorrectionModel { kSimilarity, kAffine, kHomography };

struct AdjustmentOptions {
  CorrectionModel model = CorrectionModel::kSimilarity;  ///< similarity | affine | homography
  double sigma_match_px = 2.0;  ///< σ of a feature link between frames of one UAV [mosaic px]
  /// σ of a link between frames of two UAVs [mosaic px]. Looser: their views are metres
  /// apart and at different heights, so the relief's parallax makes their links disagree
  /// with the one-plane-per-frame model by a few pixels; many such links still fix the
  /// UAVs' relative offset without bending each UAV's strip.
  double sigma_cross_px = 2.0;
  /// σ of the change of the correction between consecutive frames of one UAV, at their
  /// footprint centre and corners [mosaic px]. The pose estimate drifts slowly, while a
  /// frame's links carry the relief's parallax (a pixel or so, larger than the drift between
  /// two frames): the correction should follow the drift, not each frame's link noise.
  double sigma_smooth_px = 0.03;
  /// σ of the pose prior on the shift of the footprint centre [mosaic px]: position errors.
  double sigma_shift_px = 20.0;
  /// σ of the pose prior on the corners relative to the centre [mosaic px]: attitude and
  /// height errors. Loose: each UAV's yaw estimate drifts on its own (0.015 rad in 30 s is
  /// 20 px at 30 m), and the smoothness term already keeps the corrections from following
  /// each frame's link noise (team3: 10 px gives 3.6 px, 2 px gave 5.6 px; results/mosaic.md).
  double sigma_shape_px = 10.0;
  int iterations = 5;  ///< Gauss–Newton iterations

  Status load(const ConfigNode& node);
};

/// A feature pair linking frame i (at prior mosaic position g_i) and frame j (g_j).
struct FrameLink {
  int i = 0, j = 0;
  Eigen::Vector2d g_i, g_j;
  enum Kind { kOwn, kCross, kSmooth };
  /// kOwn: feature pair between frames of one UAV (1/σ_match); kCross: between two UAVs
  /// (1/σ_cross); kSmooth: g_i = g_j, consecutive frames of one UAV, whose corrections
  /// should differ little (1/σ_smooth).
  Kind kind = kOwn;
};

/// Prior geometry of a frame: footprint corners and centre in mosaic pixels.
struct FramePrior {
  Eigen::Vector2d centre;
  std::vector<Eigen::Vector2d> corners;
};

/// Homography corrections C_k (mosaic pixel → mosaic pixel) per frame: H_k = C_k G_k.
Expected<std::vector<Eigen::Matrix3d>> adjustFrames(const std::vector<FramePrior>& frames,
                                                    const std::vector<FrameLink>& links,
                                                    const AdjustmentOptions& options);

}  // namespace cvslam::mosaic
