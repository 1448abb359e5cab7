#pragma once
// Figures of merit of a mosaic against ground truth (docs/mosaic.md):
//  - registration error: for image points whose true ground position is known (the
//    renderer's per-pixel truth), the distance between where the mosaic put them (H · x) and
//    the mosaic pixel of their true position [mosaic px]; also after removing the best 2-D
//    similarity between the two (Umeyama), i.e. the mosaic's internal consistency when the
//    team frame itself is offset from the truth (the estimate's absolute error);
//  - PSNR of a mosaic patch against the true texture sampled on the same grid, for the plain
//    mosaic (bicubic up-sampled) and for the super-resolved patch (§4.3.4, §4.3.5).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <functional>
#include <vector>

#include "cvslam/mosaic/mosaic_builder.h"
#include "cvslam/mosaic/super_resolution.h"

namespace cvslam::mosaic {

/// An image point and the true ground position (x, y in N) of what it shows.
struct TruthPoint {
  Eigen::Vector2d pixel;
  Eigen::Vector2d ground_xy;
};

/// A placed frame's truth points.
struct PlacedTruth {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();  ///< image → mosaic pixel
  std::vector<TruthPoint> points;
};

struct ErrorStats {
  int count = 0;
  double median = 0.0, mean = 0.0, p90 = 0.0, max = 0.0;
};
ErrorStats errorStats(std::vector<double> errors);

struct RegistrationError {
  ErrorStats raw;      ///< |H x − true pixel| [mosaic px]
  ErrorStats aligned;  ///< after the best 2-D similarity of mosaic to true positions
  Eigen::Matrix3d similarity = Eigen::Matrix3d::Identity();  ///< that similarity
};
RegistrationError registrationError(const MosaicGrid& grid, const std::vector<PlacedTruth>& frames);

/// True texture on a grid: value(x, y) for every pixel centre of a `size` patch whose pixel
/// (0, 0) is mosaic pixel `origin` and whose pixels are 1/scale mosaic pixels; the mosaic
/// pixel m is taken to show the ground at grid.toGround(mosaic_to_true · m) (e.g. the
/// similarity of registrationError(), so that the global offset of the team frame does not
/// count as blur).
cv::Mat sampleTruth(const MosaicGrid& grid, const Eigen::Vector2d& origin, cv::Size size, int scale,
                    const std::function<double(double x, double y)>& value,
                    const Eigen::Matrix3d& mosaic_to_true = Eigen::Matrix3d::Identity());

/// Options of the figures the tool reports.
struct EvaluationOptions {
  double frame_period = 0.5;  ///< one frame per UAV every this many seconds [s]
  int truth_grid = 8;         ///< truth points per image side (registration error)
  int sr_patches = 12;        ///< super-resolution patches evaluated
  int sr_patch_px = 64;       ///< patch side [mosaic px]
  int sr_border_px = 4;       ///< PSNR ignores this many mosaic px at the patch border
  int sr_min_frames = 3;      ///< patches seen by fewer frames are skipped

  Status load(const ConfigNode& node);
};

/// PSNR of one patch: the plain mosaic up-sampled (bicubic) and the super-resolved patch,
/// both against the true texture on the fine grid.
struct SuperResolutionPatch {
  Eigen::Vector2d origin;  ///< mosaic pixel of the patch's (0, 0)
  int frames = 0;          ///< low-resolution frames fused
  double psnr_plain_db = 0.0;
  double psnr_sr_db = 0.0;
  cv::Mat plain, sr, truth;  ///< CV_32F on the fine grid
};

/// Super-resolves the mosaic patch at `origin` (SuperResolutionOptions::scale) from every
/// frame whose image covers it, placed by its placement H (and photometric gain/bias).
Expected<SuperResolutionPatch> evaluateSuperResolution(
    const MosaicBuilder& builder, const std::vector<FramePlacement>& placements,
    const Eigen::Vector2d& origin, const SuperResolutionOptions& sr,
    const EvaluationOptions& options, const std::function<double(double x, double y)>& truth,
    const Eigen::Matrix3d& mosaic_to_true);

}  // namespace cvslam::mosaic
