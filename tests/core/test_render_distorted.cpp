// DistortedCameraRenderer (render/distorted_camera_renderer.h): the distorted image shows at
// each pixel what the pinhole canvas shows where the camera model says that pixel's ray goes.
// Checked with OpenCV's forward model (cv::projectPoints with the radial-tangential
// coefficients), independent of the inverse the renderer builds its map from.

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <vector>

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/core/random.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/render/distorted_camera_renderer.h"
#include "render_test_scenes.h"
#include "test_paths.h"

namespace cvslam::render {
namespace {

double meanAbsDifference(const cv::Mat& distorted, const cv::Mat& canvas,
                         const StereoCameraOptions& k, const EurocCameraCalibration& c,
                         int shift_px) {
  const cv::Matx33d K(c.intrinsics(0), 0, c.intrinsics(2), 0, c.intrinsics(1), c.intrinsics(3), 0,
                      0, 1);
  const cv::Vec4d D(c.distortion(0), c.distortion(1), c.distortion(2), c.distortion(3));
  Rng rng(7);
  std::vector<cv::Point3d> rays;
  std::vector<cv::Point2d> canvas_px;
  while (rays.size() < 2000) {
    const double u = rng.uniform(2.0, k.width - 3.0), v = rng.uniform(2.0, k.height - 3.0);
    rays.emplace_back((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
    canvas_px.emplace_back(u, v);
  }
  std::vector<cv::Point2d> image_px;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, image_px);
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const int ud = static_cast<int>(std::lround(image_px[i].x));
    const int vd = static_cast<int>(std::lround(image_px[i].y));
    const int read_u = ud + shift_px;  // a wrong map would read elsewhere
    if (ud < 0 || vd < 0 || read_u < 0 || ud >= distorted.cols || vd >= distorted.rows ||
        read_u >= distorted.cols)
      continue;
    // The canvas value at the ray of the (rounded) output pixel's centre.
    std::vector<cv::Point2d> back;
    cv::undistortPoints(std::vector<cv::Point2d>{{double(ud), double(vd)}}, back, K, D);
    const double u = back[0].x * k.fx + k.cx, v = back[0].y * k.fy + k.cy;
    cv::Mat patch;
    cv::getRectSubPix(canvas, cv::Size(1, 1), cv::Point2f(float(u), float(v)), patch, CV_32F);
    sum += std::abs(patch.at<float>(0, 0) - distorted.at<uint8_t>(vd, read_u));
    ++n;
  }
  EXPECT_GT(n, 1000);
  return sum / n;
}

TEST(RenderDistorted, PixelsShowWhatTheirRaysHitInThePinholeCanvas) {
  auto calib = loadEurocStereoCalibration(test::sharedDataDir() + "/euroc_micro/mav0");
  ASSERT_TRUE(calib.ok()) << calib.status().message();
  auto world = test::makeWorld(WorldKind::kHall);
  ASSERT_TRUE(world);
  auto r = DistortedCameraRenderer::create(world, calib->left);
  ASSERT_TRUE(r.ok()) << r.status().message();
  // Barrel distortion: the canvas is wider than the image.
  EXPECT_GT(r->canvas().options().width, calib->left.width);

  const auto [p_BinN, euler] = test::hallPose();
  const Eigen::Matrix3d R_NtoC = test::euroCCamera().options().R_BtoC * rotationNavToBody(euler);
  const cv::Mat image = r->render(R_NtoC, p_BinN, 3);
  ASSERT_EQ(image.size(), cv::Size(calib->left.width, calib->left.height));
  const StereoRenderer pinhole(world, r->canvas());
  const cv::Mat canvas = pinhole.renderView(R_NtoC, p_BinN, 3).image;

  const double aligned = meanAbsDifference(image, canvas, r->canvas().options(), calib->left, 0);
  const double shifted = meanAbsDifference(image, canvas, r->canvas().options(), calib->left, 4);
  EXPECT_LT(aligned, 4.0);            // interpolation of a textured scene only
  EXPECT_GT(shifted, 3.0 * aligned);  // the check sees a 4 px error
}

TEST(RenderDistorted, RejectsAnUnsupportedModel) {
  EurocCameraCalibration c;
  c.source = "cam.yaml";
  c.distortion_model = "equidistant";
  c.width = 10;
  c.height = 10;
  auto r = DistortedCameraRenderer::create(test::makeWorld(WorldKind::kHall), c);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("equidistant"), std::string::npos);
}

}  // namespace
}  // namespace cvslam::render
