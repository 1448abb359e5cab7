#include "cvslam/render/distorted_camera_renderer.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace cvslam::render {

namespace {

// Undistorted normalised coordinates of every pixel of the calibration's image, row-major.
std::vector<cv::Point2f> undistortedGrid(const EurocCameraCalibration& c) {
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<std::size_t>(c.width) * static_cast<std::size_t>(c.height));
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u)
      pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  const cv::Matx33d K(c.intrinsics(0), 0.0, c.intrinsics(2), 0.0, c.intrinsics(1), c.intrinsics(3),
                      0.0, 0.0, 1.0);
  const cv::Vec4d D(c.distortion(0), c.distortion(1), c.distortion(2), c.distortion(3));
  std::vector<cv::Point2f> normalised;
  // Enough iterations for the strong barrel distortion of wide-angle MAV cameras.
  cv::undistortPoints(pixels, normalised, K, D, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-9));
  return normalised;
}

}  // namespace

Expected<DistortedCameraRenderer> DistortedCameraRenderer::create(
    std::shared_ptr<const World> world, const EurocCameraCalibration& calibration,
    const RenderOptions& options, double max_canvas_scale) {
  if (calibration.distortion_model != "radial-tangential")
    return Status::Error(calibration.source + ": distortion model '" +
                         calibration.distortion_model + "' not supported (radial-tangential)");
  if (calibration.width <= 0 || calibration.height <= 0)
    return Status::Error(calibration.source + ": resolution must be positive");
  const std::vector<cv::Point2f> normalised = undistortedGrid(calibration);

  // The canvas keeps the focal lengths and spans every undistorted ray, plus one pixel for
  // the bilinear footprint.
  const double fx = calibration.intrinsics(0), fy = calibration.intrinsics(1);
  float x_lo = 0.0F, x_hi = 0.0F, y_lo = 0.0F, y_hi = 0.0F;
  for (const cv::Point2f& p : normalised) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      return Status::Error(calibration.source + ": distortion model does not invert");
    x_lo = std::min(x_lo, p.x), x_hi = std::max(x_hi, p.x);
    y_lo = std::min(y_lo, p.y), y_hi = std::max(y_hi, p.y);
  }
  StereoCameraOptions canvas;
  canvas.fx = fx;
  canvas.fy = fy;
  canvas.cx = -x_lo * fx + 1.0;
  canvas.cy = -y_lo * fy + 1.0;
  canvas.width = static_cast<int>(std::ceil((x_hi - x_lo) * fx)) + 3;
  canvas.height = static_cast<int>(std::ceil((y_hi - y_lo) * fy)) + 3;
  if (canvas.width > max_canvas_scale * calibration.width ||
      canvas.height > max_canvas_scale * calibration.height)
    return Status::Error(calibration.source + ": distorted field of view too wide to render (" +
                         std::to_string(canvas.width) + "x" + std::to_string(canvas.height) +
                         " px canvas)");
  canvas.R_BtoC = Eigen::Matrix3d::Identity();

  DistortedCameraRenderer r;
  r.calibration_ = calibration;
  r.renderer_ = std::make_shared<StereoRenderer>(std::move(world), StereoCamera(canvas), options);
  r.map_x_.create(calibration.height, calibration.width, CV_32F);
  r.map_y_.create(calibration.height, calibration.width, CV_32F);
  for (int v = 0; v < calibration.height; ++v) {
    for (int u = 0; u < calibration.width; ++u) {
      const cv::Point2f& p = normalised[static_cast<std::size_t>(v * calibration.width + u)];
      r.map_x_.at<float>(v, u) = static_cast<float>(fx * p.x + canvas.cx);
      r.map_y_.at<float>(v, u) = static_cast<float>(fy * p.y + canvas.cy);
    }
  }
  return r;
}

cv::Mat DistortedCameraRenderer::render(const Eigen::Matrix3d& R_NtoC,
                                        const Eigen::Vector3d& p_CinN,
                                        uint64_t noise_stream) const {
  const RenderedImage pinhole = renderer_->renderView(R_NtoC, p_CinN, noise_stream);
  cv::Mat out;
  cv::remap(pinhole.image, out, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

}  // namespace cvslam::render
