#include "cvslam/render/view_changes.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/render/world.h"

namespace cvslam::render {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kAltitudeM = 10.0;         // the thesis's UAV flies ~10 m up (Table 5.6)
constexpr double kGroundFocalFactor = 0.6;  // focal = 0.6 × side: a 80° field of view

cv::Matx33d aboutCentre(const cv::Matx33d& m, cv::Size size) {
  const double cx = 0.5 * (size.width - 1), cy = 0.5 * (size.height - 1);
  const cv::Matx33d to(1, 0, -cx, 0, 1, -cy, 0, 0, 1), back(1, 0, cx, 0, 1, cy, 0, 0, 1);
  return back * m * to;
}

}  // namespace

Expected<cv::Mat> renderGroundImage(int side, uint64_t seed) {
  if (side < 64) return Status::Error("renderGroundImage: side must be >= 64");
  WorldOptions w;
  w.kind = WorldKind::kAerial;
  w.seed = seed;
  w.texture.seed = seed;
  w.texture.variant = TextureVariant::kHigh;
  auto world = World::create(w);
  if (!world.ok()) return world.status();
  StereoCameraOptions c;  // default: looking down
  c.width = c.height = side;
  c.fx = c.fy = kGroundFocalFactor * side;
  c.cx = c.cy = 0.5 * side;
  const StereoRenderer renderer(*world, StereoCamera(c));
  return renderer.render(Eigen::Vector3d(3.0, 7.0, -kAltitudeM), Eigen::Vector3d::Zero())
      .left.image;
}

ViewChange rotationChange(double degrees, cv::Size size) {
  ViewChange v;
  v.family = "rotation";
  v.amount = degrees;
  const double c = std::cos(degrees * kDeg), s = std::sin(degrees * kDeg);
  v.H = aboutCentre(cv::Matx33d(c, -s, 0, s, c, 0, 0, 0, 1), size);
  return v;
}

ViewChange scaleChange(double factor, cv::Size size) {
  ViewChange v;
  v.family = "scale";
  v.amount = factor;
  v.H = aboutCentre(cv::Matx33d(factor, 0, 0, 0, factor, 0, 0, 0, 1), size);
  return v;
}

ViewChange viewpointChange(double degrees, cv::Size size, double focal_px) {
  ViewChange v;
  v.family = "viewpoint";
  v.amount = degrees;
  const double cx = 0.5 * (size.width - 1), cy = 0.5 * (size.height - 1);
  const cv::Matx33d K(focal_px, 0, cx, 0, focal_px, cy, 0, 0, 1);
  const double a = degrees * kDeg;
  const cv::Matx33d R(1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a));
  // Plane z = d (n = e_z) seen from the origin; the turned camera looks at the same point P0 =
  // d e_z from the same distance: C = P0 − Rᵀ d e_z.
  const double d = 1.0;
  const cv::Vec3d C = cv::Vec3d(0, 0, d) - R.t() * cv::Vec3d(0, 0, d);
  const cv::Matx33d M =
      cv::Matx33d::eye() - cv::Matx33d(0, 0, C[0], 0, 0, C[1], 0, 0, C[2]) * (1.0 / d);
  v.H = K * R * M * K.inv();
  v.H *= 1.0 / v.H(2, 2);
  return v;
}

ViewChange blurChange(double sigma) {
  ViewChange v;
  v.family = "blur";
  v.amount = sigma;
  v.blur_sigma = sigma;
  return v;
}

ViewChange illuminationChange(double gain, double gamma) {
  ViewChange v;
  v.family = "illumination";
  v.amount = gain;
  v.gain = gain;
  v.gamma = gamma;
  return v;
}

ViewPair makeViewPair(const cv::Mat& ground, cv::Size size, const ViewChange& change) {
  ViewPair p;
  p.change = change;
  const int ox = (ground.cols - size.width) / 2, oy = (ground.rows - size.height) / 2;
  p.reference = ground(cv::Rect(ox, oy, size.width, size.height)).clone();
  const cv::Matx33d T(1, 0, -ox, 0, 1, -oy, 0, 0, 1);  // ground → reference
  cv::warpPerspective(ground, p.transformed, cv::Mat(change.H * T), size, cv::INTER_LINEAR,
                      cv::BORDER_REFLECT_101);
  if (change.blur_sigma > 0)
    cv::GaussianBlur(p.transformed, p.transformed, cv::Size(), change.blur_sigma);
  if (change.gain != 1.0 || change.gamma != 1.0) {
    cv::Mat lut(1, 256, CV_8U);
    for (int i = 0; i < 256; ++i)
      lut.at<uint8_t>(i) =
          cv::saturate_cast<uint8_t>(255.0 * change.gain * std::pow(i / 255.0, change.gamma));
    cv::LUT(p.transformed, lut, p.transformed);
  }
  return p;
}

}  // namespace cvslam::render
