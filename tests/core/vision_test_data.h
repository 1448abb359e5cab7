#pragma once
// Real EuRoC material for the vision tests: stereo pairs of euroc_micro (V1_01_easy, paired by
// timestamp as a reader must — cam1 lists more frames than cam0) and a minimal reader of
// EuRoC's camera sensor.yaml into a StereoCalibration (the project's full parser lives
// elsewhere; this one reads only what the tests need).

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "cvslam/vision/stereo_calibration.h"
#include "cvslam/vision/stereo_rectifier.h"
#include "test_paths.h"

namespace cvslam::test {

inline std::string eurocMicroDir() {
  return sharedDataDir() + "/euroc_micro/mav0";
}

/// Timestamps [ns] (as text) present in both cam0 and cam1, in order.
inline std::vector<std::string> eurocStereoStamps() {
  auto read = [](const std::string& csv) {
    std::vector<std::string> stamps;
    std::ifstream is(csv);
    std::string line;
    while (std::getline(is, line)) {
      if (line.empty() || line[0] == '#') continue;
      stamps.push_back(line.substr(0, line.find(',')));
    }
    return stamps;
  };
  const auto left = read(eurocMicroDir() + "/cam0/data.csv");
  const auto right = read(eurocMicroDir() + "/cam1/data.csv");
  const std::set<std::string> r(right.begin(), right.end());
  std::vector<std::string> both;
  for (const auto& s : left)
    if (r.count(s)) both.push_back(s);
  return both;
}

/// Raw (distorted) grey images of one stereo pair.
inline bool loadEurocPair(const std::string& stamp, cv::Mat* left, cv::Mat* right) {
  *left = cv::imread(eurocMicroDir() + "/cam0/data/" + stamp + ".png", cv::IMREAD_GRAYSCALE);
  *right = cv::imread(eurocMicroDir() + "/cam1/data/" + stamp + ".png", cv::IMREAD_GRAYSCALE);
  return !left->empty() && !right->empty();
}

/// The rectified real pairs of the real-stereo tests: frames 0, 30 and 60 of euroc_micro
/// (three views of the Vicon room). False when one cannot be read or rectified.
inline bool rectifiedEurocPairs(const vision::StereoRectifier& rect,
                                std::vector<std::pair<cv::Mat, cv::Mat>>* pairs) {
  const auto stamps = eurocStereoStamps();
  if (stamps.size() <= 60) return false;
  for (std::size_t k : {0u, 30u, 60u}) {
    cv::Mat l, r, lr, rr;
    if (!loadEurocPair(stamps[k], &l, &r) || !rect.rectify(l, r, &lr, &rr).ok()) return false;
    pairs->emplace_back(lr, rr);
  }
  return true;
}

inline bool readEurocCamera(const std::string& yaml, vision::CameraCalibration* c) {
  cv::FileStorage fs(yaml, cv::FileStorage::READ);
  if (!fs.isOpened()) return false;
  std::vector<double> intr;
  std::vector<double> dist;
  std::vector<int> res;
  std::vector<double> T;
  fs["intrinsics"] >> intr;
  fs["distortion_coefficients"] >> dist;
  fs["resolution"] >> res;
  fs["T_BS"]["data"] >> T;
  if (intr.size() != 4 || res.size() != 2 || T.size() != 16) return false;
  c->fx = intr[0];
  c->fy = intr[1];
  c->cx = intr[2];
  c->cy = intr[3];
  c->distortion = dist;
  c->width = res[0];
  c->height = res[1];
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = T[static_cast<std::size_t>(i)];
  c->T_CtoB.matrix() = m;
  return true;
}

inline bool eurocCalibration(vision::StereoCalibration* calib) {
  return readEurocCamera(eurocMicroDir() + "/cam0/sensor.yaml", &calib->left) &&
         readEurocCamera(eurocMicroDir() + "/cam1/sensor.yaml", &calib->right);
}

/// 320×240 grey image of 6 Gaussian blobs (amplitude 150 on 60) at sub-pixel centres, σ =
/// sigma_first, +1, +2 px along each row of blobs.
inline cv::Mat blobImage(double sigma_first, std::vector<cv::Point2f>* centres,
                         std::vector<double>* sigmas) {
  cv::Mat img(240, 320, CV_32F, cv::Scalar(60.0));
  for (int by = 0; by < 2; ++by)
    for (int bx = 0; bx < 3; ++bx) {
      const cv::Point2f c(60.0f + 100.3f * bx, 65.0f + 110.35f * by);
      const double sigma = sigma_first + bx;
      centres->push_back(c);
      sigmas->push_back(sigma);
      for (int v = 0; v < img.rows; ++v)
        for (int u = 0; u < img.cols; ++u) {
          const double r2 = (u - c.x) * (u - c.x) + (v - c.y) * (v - c.y);
          img.at<float>(v, u) += static_cast<float>(150.0 * std::exp(-r2 / (2 * sigma * sigma)));
        }
    }
  cv::Mat gray;
  img.convertTo(gray, CV_8U);
  return gray;
}

/// Stereo matches of the real rectified EuRoC pairs: how many, the median row error and the
/// fraction "plausible" (row within 1 px, depth f·b/d between 0.4 and 12 m: the Vicon room).
struct RealStereoSummary {
  int total = 0;
  double median_row_error = 0.0;
  double plausible = 0.0;
};
inline RealStereoSummary summariseRealStereo(
    const std::vector<std::pair<cv::Point2f, cv::Point2f>>& matches, double f, double baseline) {
  RealStereoSummary s;
  std::vector<double> row_err;
  int good = 0;
  for (const auto& [pl, pr] : matches) {
    const double dv = std::abs(pl.y - pr.y);
    const double z = f * baseline / (pl.x - pr.x);  // eq. 4.10
    row_err.push_back(dv);
    if (dv <= 1.0 && z > 0.4 && z < 12.0) ++good;
  }
  s.total = static_cast<int>(matches.size());
  if (row_err.empty()) return s;
  std::nth_element(row_err.begin(), row_err.begin() + static_cast<long>(row_err.size() / 2),
                   row_err.end());
  s.median_row_error = row_err[row_err.size() / 2];
  s.plausible = static_cast<double>(good) / s.total;
  return s;
}

}  // namespace cvslam::test
