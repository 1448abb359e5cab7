#pragma once
// The mosaicking algorithm (thesis §4.3.3.2, Diagram 2; cooperative use §6.5): camera images
// are placed in one ground-plane mosaic, north up, in the team frame N.
//
//  1. Prior (add()): the estimated camera pose and the ground plane under the frame
//     D = a·x + b·y + c (fitted to the estimated landmarks it sees; else D = ground_down) give
//     the homography image → ground (x, y) → mosaic pixel G_k: the ground point
//     X = (x, y, D) projects to u ≅ K R_NtoC [e1 + a·e3, e2 + b·e3, c·e3 − p_CinN] [x y 1]ᵀ.
//     The plane matters: terrain 2 m below the level plane seen from 10 m makes the prior's
//     scale 20 % wrong, and differently along a flight.
//  2. Geometric registration (§4.3.3.1, add()): adaptive SIFT of the new image against the
//     images already added whose prior footprints overlap it most (any UAV: the cooperative
//     mosaic links the team's views), matches gated around G_j⁻¹ G_k, RANSAC homography; the
//     inlier pairs become links. Accepted when they have min_inliers and the homography moves
//     no image corner more than max_correction_px from the prior.
//  3. Global adjustment (finish(), mosaic_adjustment.h): one affine correction per frame
//     from all links and the pose priors, so that registration errors do not accumulate
//     along a flight as they do when each frame is chained to the previous one.
//  4. Photometric registration (§4.3.3.3, finish()): in time order, gain/bias of each warped
//     image against the mosaic built so far where both are known (both smoothed first, so
//     that sub-pixel misregistration does not read as contrast loss), applied to the image.
//  5. Blending (finish()): each warped image is added with a feathering weight (distance to
//     the image border), so seams between frames fade instead of stepping.
//
// YAML (section `mosaic`):
//   gsd: 0.02   margin: 2.0   ground_down: 0.0   register: true   min_overlap: 0.2
//   max_neighbours: 6   max_links_per_pair: 40   max_correction_px: 60   feather_px: 30
//   max_megapixels: 100   min_ground_points: 8   min_ground_spread: 1.0   adjustment:
//   {sigma_match_px: 1.0, sigma_prior_px: 20.0}

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/mosaic/geometric_registration.h"
#include "cvslam/mosaic/mosaic_adjustment.h"
#include "cvslam/mosaic/photometric_registration.h"

namespace cvslam::mosaic {

struct MosaicOptions {
  double gsd = 0.02;                ///< ground size of a mosaic pixel [m]
  double margin = 2.0;              ///< mosaic extends this beyond the prior footprints [m]
  double ground_down = 0.0;         ///< D of the ground plane used by the pose prior [m]
  bool register_frames = true;      ///< key `register`: refine the prior by registration
  double min_overlap = 0.2;         ///< prior footprint overlap needed to try a pair
  int max_neighbours = 6;           ///< earlier frames (most overlapping) registered to
  int max_links_per_pair = 40;      ///< inlier pairs kept per registered pair (spread)
  double max_correction_px = 60.0;  ///< larger corrections of the prior are rejected [px]
  double feather_px = 30.0;         ///< blending weight ramps up over this from the border
  double max_megapixels = 100.0;    ///< refuse larger mosaics (memory: 8 bytes per pixel)
  int min_ground_points = 8;        ///< landmarks needed to fit a frame's ground plane
  double min_ground_spread = 1.0;   ///< … spread over at least this (else level plane) [m]
  AdjustmentOptions adjustment;     ///< section `adjustment`

  Status load(const ConfigNode& node);
};

/// A north-up ground grid: column = east (y), row = south (−x); pixel centres are integers.
struct MosaicGrid {
  double x_max = 0.0, y_min = 0.0;  ///< N coordinates of pixel (0, 0) [m]
  double gsd = 0.02;                ///< [m per pixel]
  int cols = 0, rows = 0;

  /// Homography ground (x, y, 1) → mosaic pixel.
  Eigen::Matrix3d groundToPixel() const;
  Eigen::Vector2d toPixel(const Eigen::Vector2d& xy) const;
  Eigen::Vector2d toGround(const Eigen::Vector2d& pixel) const;
};

/// One camera image with its estimated pose (the prior).
struct MosaicFrame {
  cv::Mat image;  ///< CV_8U grey
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_NtoC = Eigen::Matrix3d::Identity();  ///< estimated orientation
  Eigen::Vector3d p_CinN = Eigen::Vector3d::Zero();      ///< estimated camera centre [m]
  int agent = 0;                                         ///< UAV id
  /// Local ground plane under this frame, D = a·x + b·y + c as (a, b, c) (e.g. fitted to the
  /// estimated landmarks it sees, groundPlaneFromPoints()); none: the level plane
  /// D = ground_down of the options.
  std::optional<Eigen::Vector3d> ground_plane;
};

/// Least-squares plane D = a·x + b·y + c through the points (in N) that the frame's camera
/// sees inside its image; a level plane at their median D when they are too few or too
/// clustered for a tilt (< min_points, or a footprint spread below min_spread metres); none
/// below min_points / 2 points.
std::optional<Eigen::Vector3d> groundPlaneFromPoints(const MosaicFrame& frame,
                                                     const std::vector<Eigen::Vector3d>& points,
                                                     int min_points, double min_spread);

/// Image → ground (x, y) homography of a camera above the plane frame.ground_plane, else the
/// level plane D = ground_down.
Eigen::Matrix3d imageToGround(const MosaicFrame& frame, double ground_down);

/// What happened to one frame.
struct FramePlacement {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();      ///< image pixel → mosaic pixel
  Eigen::Matrix3d prior = Eigen::Matrix3d::Identity();  ///< pose-only prior G_k
  int registered_pairs = 0;                             ///< earlier frames it was registered to
  int links = 0;                                        ///< feature links to earlier frames
  GainBias photometric;                                 ///< applied gain/bias (1, 0 if none)
};

class MosaicBuilder {
 public:
  MosaicBuilder(const MosaicGrid& grid, const MosaicOptions& mosaic,
                const RegistrationOptions& registration, const PhotometricOptions& photometric);

  /// Grid covering the prior footprints of all frames plus the margin.
  static Expected<MosaicGrid> gridCovering(const std::vector<MosaicFrame>& frames,
                                           const MosaicOptions& options);

  /// Adds one frame (in time order) and registers it to the earlier ones.
  Status add(const MosaicFrame& frame);
  /// Adjusts all frames, then blends them; placements in the order added.
  Expected<std::vector<FramePlacement>> finish();

  const MosaicGrid& grid() const { return grid_; }
  /// The blended mosaic (CV_8U); `background` where nothing was mapped.
  cv::Mat image(int background = 0) const;
  /// Blending weight sum per pixel (CV_32F, 0 = unmapped).
  const cv::Mat& weight() const { return weight_; }
  /// The frames added so far (images and priors), e.g. for super-resolution.
  const std::vector<MosaicFrame>& frames() const { return frames_; }

 private:
  struct Stored {
    vision::Features features;
    FramePrior footprint;
    cv::Rect box;  // bounding box of the prior footprint [mosaic px]
  };
  void linkTo(std::size_t k, std::size_t j);
  GainBias photometricCorrection(const cv::Mat& image, const Eigen::Matrix3d& H) const;
  void blend(const cv::Mat& image, const Eigen::Matrix3d& H);

  MosaicGrid grid_;
  MosaicOptions o_;
  RegistrationOptions reg_;
  PhotometricOptions photo_;
  std::vector<MosaicFrame> frames_;
  std::vector<Stored> stored_;
  std::vector<FramePlacement> placements_;
  std::vector<FrameLink> links_;
  cv::Mat sum_, weight_;  // CV_32F accumulators
  cv::Mat feather_;       // per image size: border weight
};

}  // namespace cvslam::mosaic
