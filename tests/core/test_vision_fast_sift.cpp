// Fast SIFT (fast_sift.h, sift_scale_space.h, sift_descriptor.h) and the front end that detects
// on the left image only and searches the right along rows (row_stereo_search.h): blobs found
// at their centre and scale, descriptors equal to OpenCV's for the same keypoints (so the SIFT
// vocabulary and the SIFT gates apply), stereo precision on a pair of known disparity and on
// the real rectified EuRoC pairs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/fast_sift.h"
#include "cvslam/vision/stereo_front_end.h"
#include "cvslam/vision/stereo_rectifier.h"
#include "vision_test_data.h"

namespace cvslam::vision {
namespace {

cv::Mat realLeft(std::size_t k) {
  const auto stamps = test::eurocStereoStamps();
  cv::Mat l, r;
  if (stamps.size() <= k || !test::loadEurocPair(stamps[k], &l, &r)) return cv::Mat();
  return l;
}

// A 2-D Gaussian blob of σ_b is the scale-normalised DoG's extremum at σ ≈ σ_b (size = 2σ),
// at its centre. (S1 lowered: this flat image would otherwise get k ← k², one level per
// octave, and the test is about localisation, not eq. 4.6.)
TEST(VisionFastSift, FindsBlobsAtTheirCentreAndScale) {
  std::vector<cv::Point2f> centres;
  std::vector<double> sigmas;
  const cv::Mat gray = test::blobImage(3.0, &centres, &sigmas);
  AdaptiveSiftOptions a;
  a.min_features = 1;
  a.energy_low = 0.01;
  FastSift sift(a, FastSiftOptions());
  Features f;
  ASSERT_TRUE(sift.detectAndDescribe(gray, &f).ok());
  ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.size()));
  ASSERT_EQ(f.descriptors.cols, 128);
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const cv::KeyPoint* best = nullptr;
    for (const cv::KeyPoint& kp : f.keypoints)
      if (!best || cv::norm(kp.pt - centres[i]) < cv::norm(best->pt - centres[i])) best = &kp;
    ASSERT_NE(best, nullptr);
    EXPECT_LT(cv::norm(best->pt - centres[i]), 0.1) << centres[i] << " " << best->pt;
    EXPECT_NEAR(best->size / 2.0 / sigmas[i], 1.0, 0.25) << centres[i] << " " << best->size;
    EXPECT_GE(best->angle, 0.0f);
  }
}

// The descriptors are OpenCV's for the same keypoints and angles (OpenCV computes them for
// given keypoints on the same un-doubled pyramid): equal up to float rounding (±2 of 0..255),
// hence the SIFT vocabulary and the association's SIFT gates hold for them. (The scale space
// from the input resolution, as OpenCV's; by default a 752×480 image is resampled first.)
TEST(VisionFastSift, DescriptorsAreOpenCvSiftDescriptors) {
  const cv::Mat img = realLeft(10);
  ASSERT_FALSE(img.empty());
  const AdaptiveSiftOptions a;
  FastSiftOptions fo;
  fo.max_base_side = 0;
  FastSift sift(a, fo);
  Features f;
  ScaleFactorChoice c;
  std::vector<cv::KeyPoint> kps;
  ASSERT_TRUE(sift.detect(img, &kps, &c).ok());
  ASSERT_GE(kps.size(), static_cast<std::size_t>(a.min_features));
  sift.describe(&kps, &f.descriptors);
  auto ocv = cv::SIFT::create(0, c.octave_layers, 0.04, a.edge_threshold, a.sigma0, CV_8U);
  std::vector<cv::KeyPoint> same = kps;
  cv::Mat desc;
  ocv->compute(img, same, desc);
  ASSERT_EQ(same.size(), kps.size());
  int far = 0;
  for (int i = 0; i < desc.rows; ++i) {
    const double linf = cv::norm(desc.row(i), f.descriptors.row(i), cv::NORM_INF);
    if (linf > 2.0) ++far;
  }
  std::cout << "[figures] fast SIFT descriptors: " << desc.rows << ", " << far
            << " differ from OpenCV's by more than 2\n";
  EXPECT_LE(far, desc.rows / 100);
}

struct StereoCheck {
  std::size_t matches = 0;
  double precision = 0.0;
};

StereoFrontEndOptions fastOptions(double f, double baseline, double min_depth) {
  StereoFrontEndOptions o;
  o.detector.type = DetectorType::kFastSift;
  o.stereo.focal_px = f;
  o.stereo.baseline_m = baseline;
  o.stereo.min_depth_m = min_depth;
  return o;
}

// The fast front end on a real image shifted by a known disparity field (as
// test_vision_stereo.cpp): a match is right within 1 px in disparity and row.
double knownDisparity(double v, int rows) {
  return 6.0 + 30.0 * v / rows;
}

// The right image of `left` under knownDisparity().
cv::Mat shiftedRight(const cv::Mat& left) {
  cv::Mat map_x(left.size(), CV_32F), map_y(left.size(), CV_32F);
  for (int v = 0; v < left.rows; ++v)
    for (int u = 0; u < left.cols; ++u) {
      map_x.at<float>(v, u) = static_cast<float>(u + knownDisparity(v, left.rows));
      map_y.at<float>(v, u) = static_cast<float>(v);
    }
  cv::Mat right;
  cv::remap(left, right, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  return right;
}

TEST(VisionFastSift, FrontEndPrecisionAgainstKnownDisparity) {
  const cv::Mat left = realLeft(20);
  ASSERT_FALSE(left.empty());
  auto disparity = [&](double v) { return knownDisparity(v, left.rows); };
  const cv::Mat right = shiftedRight(left);
  auto fe = StereoFrontEnd::create(fastOptions(450.0, 0.11, 1.0), nullptr);
  ASSERT_TRUE(fe.ok()) << fe.status().message();
  std::vector<StereoObservation> obs;
  ASSERT_TRUE(fe->process(left, right, &obs).ok());
  int correct = 0;
  for (const StereoObservation& o : obs) {
    const double d = o.z(0) - o.z(2);
    if (std::abs(d - disparity(o.z(1))) < 1.0 && std::abs(o.z(1) - o.z(3)) < 1.0) ++correct;
  }
  const double precision = obs.empty() ? 0.0 : static_cast<double>(correct) / obs.size();
  std::cout << "[figures] fast front end, synthetic stereo: " << fe->lastFrame().left_detected
            << " left keypoints, " << obs.size() << " matches, precision " << precision << "\n";
  EXPECT_GE(obs.size(), 150u);
  EXPECT_GE(precision, 0.99);
  for (std::size_t i = 0; i < fe->lastFrame().left.size(); ++i)  // described: matched only
    EXPECT_EQ(fe->lastFrame().matches[i].left, static_cast<int>(i));
}

// max_observations keeps the matches inside priority regions (where the map predicts a
// landmark) before better-scored ones elsewhere, and describes only the kept ones.
TEST(VisionFastSift, MaxObservationsKeepsPriorityRegionsFirst) {
  const cv::Mat left = realLeft(20);
  ASSERT_FALSE(left.empty());
  const cv::Mat right = shiftedRight(left);
  auto all = StereoFrontEnd::create(fastOptions(450.0, 0.11, 1.0), nullptr);
  ASSERT_TRUE(all.ok()) << all.status().message();
  std::vector<StereoObservation> every;
  ASSERT_TRUE(all->process(left, right, &every).ok());
  ASSERT_GE(every.size(), 150u);
  // The ten worst-scored matches (largest 1 − ZNCC) are the ones a plain cap drops first.
  std::vector<StereoMatch> by_score = all->lastFrame().matches;
  std::sort(by_score.begin(), by_score.end(),
            [](const StereoMatch& a, const StereoMatch& b) { return a.distance > b.distance; });
  std::vector<PriorityRegion> regions;
  for (std::size_t k = 0; k < 10; ++k) {
    const cv::Point2f p =
        all->lastFrame().left.keypoints[static_cast<std::size_t>(by_score[k].left)].pt;
    regions.push_back({p, cv::Point2f(1.0f, 1.0f)});
  }
  auto keptCount = [&](const std::vector<StereoObservation>& obs) {
    int found = 0;
    for (const PriorityRegion& r : regions)
      for (const StereoObservation& o : obs)
        if (std::abs(o.z(0) - r.center.x) < 1e-3 && std::abs(o.z(1) - r.center.y) < 1e-3) {
          ++found;
          break;
        }
    return found;
  };
  StereoFrontEndOptions capped = fastOptions(450.0, 0.11, 1.0);
  capped.max_observations = 40;
  auto fe = StereoFrontEnd::create(capped, nullptr);
  ASSERT_TRUE(fe.ok()) << fe.status().message();
  std::vector<StereoObservation> obs;
  ASSERT_TRUE(fe->process(left, right, &obs).ok());
  EXPECT_EQ(obs.size(), 40u);
  EXPECT_LE(keptCount(obs), 1);  // without regions the worst are dropped
  ASSERT_TRUE(fe->process(left, right, &obs, &regions).ok());
  EXPECT_EQ(obs.size(), 40u);
  EXPECT_EQ(fe->lastFrame().left.descriptors.rows, 40);  // the rest were not described
  EXPECT_EQ(keptCount(obs), 10);
  EXPECT_GE(fe->lastFrame().prioritised, 10);
  EXPECT_GT(fe->lastFrame().timings.describe_ms, 0.0);
  // fast_sift's describe_budget caps the same way.
  StereoFrontEndOptions budget = fastOptions(450.0, 0.11, 1.0);
  budget.detector.fast_sift.describe_budget = 40;
  auto fb = StereoFrontEnd::create(budget, nullptr);
  ASSERT_TRUE(fb.ok()) << fb.status().message();
  EXPECT_EQ(fb->keptMatches(), 40);
  std::vector<StereoObservation> obs_budget;
  ASSERT_TRUE(fb->process(left, right, &obs_budget, &regions).ok());
  ASSERT_EQ(obs_budget.size(), obs.size());
  for (std::size_t i = 0; i < obs.size(); ++i) EXPECT_EQ(obs_budget[i].z, obs[i].z);
}

// The real rectified EuRoC pairs (as VisionStereoReal): rows aligned, depths plausible.
TEST(VisionFastSift, FrontEndOnRealPairsIsRowAlignedAndPlausible) {
  StereoCalibration calib;
  ASSERT_TRUE(test::eurocCalibration(&calib));
  auto rect = StereoRectifier::create(calib);
  ASSERT_TRUE(rect.ok()) << rect.status().message();
  const RectifiedStereo& r = rect->rectified();
  StereoFrontEndOptions o = fastOptions(r.f, r.baseline, 0.4);
  o.stereo.max_vertical_disparity_px = 4.0;  // rows refined within ±1 px
  auto fe = StereoFrontEnd::create(o, nullptr);
  ASSERT_TRUE(fe.ok()) << fe.status().message();
  std::vector<std::pair<cv::Mat, cv::Mat>> pairs;
  ASSERT_TRUE(test::rectifiedEurocPairs(*rect, &pairs));
  std::vector<std::pair<cv::Point2f, cv::Point2f>> matches;
  for (const auto& [lr, rr] : pairs) {
    std::vector<StereoObservation> obs;
    ASSERT_TRUE(fe->process(lr, rr, &obs).ok());
    for (const StereoObservation& ob : obs)
      matches.push_back({cv::Point2f(static_cast<float>(ob.z(0)), static_cast<float>(ob.z(1))),
                         cv::Point2f(static_cast<float>(ob.z(2)), static_cast<float>(ob.z(3)))});
  }
  const test::RealStereoSummary s = test::summariseRealStereo(matches, r.f, r.baseline);
  ASSERT_GT(s.total, 150);
  std::cout << "[figures] fast front end, real rectified EuRoC: " << s.total
            << " matches in 3 pairs, median row error " << s.median_row_error << " px, plausible "
            << s.plausible << "\n";
  EXPECT_LT(s.median_row_error, 0.5);
  EXPECT_GE(s.plausible, 0.98);
}

TEST(VisionFastSift, OptionsLoadAndErrors) {
  auto cfg = ConfigNode::fromString(
      "front_end:\n"
      "  detector: {type: fast_sift,\n"
      "             fast_sift: {grid_cols: 4, grid_rows: 3, max_octaves: 5, max_base_side: 300,\n"
      "                         describe_budget: 120}}\n"
      "  row_search: {patch_radius: 4, min_zncc: 0.9, uniqueness: 0.5, min_patch_std: 1.0}\n",
      "f.yaml");
  ASSERT_TRUE(cfg.ok());
  StereoFrontEndOptions o;
  ASSERT_TRUE(o.load(cfg->child("front_end")).ok()) << cfg->status().message();
  EXPECT_TRUE(cfg->finish().ok()) << cfg->finish().message();
  EXPECT_EQ(o.detector.type, DetectorType::kFastSift);
  EXPECT_EQ(o.detector.fast_sift.grid_cols, 4);
  EXPECT_EQ(o.detector.fast_sift.max_octaves, 5);
  EXPECT_EQ(o.detector.fast_sift.max_base_side, 300);
  EXPECT_EQ(o.detector.fast_sift.describe_budget, 120);
  EXPECT_DOUBLE_EQ(o.detector.fast_sift.baseScale(cv::Size(600, 400)), 0.5);
  EXPECT_DOUBLE_EQ(o.detector.fast_sift.baseScale(cv::Size(300, 200)), 1.0);
  EXPECT_EQ(o.row_search.patch_radius, 4);
  EXPECT_DOUBLE_EQ(o.row_search.uniqueness, 0.5);
  for (const char* bad :
       {"{row_search: {patch_radius: 0}}", "{row_search: {uniqueness: 1.5}}",
        "{detector: {fast_sift: {grid_cols: 4, grid_rows: 0}}}",
        "{detector: {fast_sift: {max_octaves: 0}}}", "{detector: {fast_sift: {max_base_side: 10}}}",
        "{detector: {fast_sift: {describe_budget: -1}}}"}) {
    auto c = ConfigNode::fromString(std::string("front_end: ") + bad, "f.yaml");
    ASSERT_TRUE(c.ok());
    StereoFrontEndOptions x;
    EXPECT_FALSE(x.load(c->child("front_end")).ok()) << bad;
  }
}

}  // namespace
}  // namespace cvslam::vision
