#pragma once
// Real EuRoC material for the vision tests: stereo pairs of euroc_micro (V1_01_easy, paired by
// timestamp as a reader must — cam1 lists more frames than cam0) and a minimal reader of
// EuRoC's camera sensor.yaml into a StereoCalibration (the project's full parser lives
// elsewhere; this one reads only what the tests need).

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "cvslam/vision/stereo_calibration.h"
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

}  // namespace cvslam::test
