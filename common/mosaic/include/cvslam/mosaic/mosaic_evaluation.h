#pragma once
// Figures of merit of a mosaic against ground truth (docs/mosaic.md):
//  - registration error: for image points whose true ground position is known (the
//    renderer's per-pixel truth), the distance between where the mosaic put them (H · x) and
//    the mosaic pixel of their true position [mosaic px]; also after removing the best 2-D
//    similarity between the two (Umeyama), i.e. the mosaic's internal consistency when the
//    team frame itself is offset from the truth (the estimate's absolute error);
//  - PSNR of a mosaic patch against the true texture sampled on the same grid.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <functional>
#include <vector>

#include "cvslam/mosaic/mosaic_builder.h"

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
/// (0, 0) is mosaic pixel `origin` and whose pixels are 1/scale mosaic pixels.
cv::Mat sampleTruth(const MosaicGrid& grid, const Eigen::Vector2d& origin, cv::Size size, int scale,
                    const std::function<double(double x, double y)>& value);

}  // namespace cvslam::mosaic
