#include "cvslam/render/rendered_image.h"

#include <cmath>
#include <limits>

namespace cvslam::render {

std::optional<SurfacePoint> RenderedImage::surfaceAt(double u, double v) const {
  const int i = static_cast<int>(std::lround(u));
  const int j = static_cast<int>(std::lround(v));
  if (i < 0 || j < 0 || i >= triangle_ids.cols || j >= triangle_ids.rows) return std::nullopt;
  const int id = triangle_ids(j, i);
  if (id < 0) return std::nullopt;
  const double w = planes[static_cast<std::size_t>(id)].dot(Eigen::Vector3d(u, v, 1.0));
  if (!(w > 0)) return std::nullopt;
  const double z = 1.0 / w;
  const Eigen::Vector3d p_C((u - intrinsics.cx) / intrinsics.fx * z,
                            (v - intrinsics.cy) / intrinsics.fy * z, z);
  return SurfacePoint{R_NtoC.transpose() * p_C + p_CinN, z};
}

cv::Mat1f RenderedImage::depthMap() const {
  cv::Mat1f depth(triangle_ids.size(), std::numeric_limits<float>::quiet_NaN());
  for (int j = 0; j < depth.rows; ++j)
    for (int i = 0; i < depth.cols; ++i) {
      const int id = triangle_ids(j, i);
      if (id >= 0)
        depth(j, i) = static_cast<float>(
            1.0 / planes[static_cast<std::size_t>(id)].dot(Eigen::Vector3d(i, j, 1.0)));
    }
  return depth;
}

}  // namespace cvslam::render
