#include "cvslam/vision/keypoint_grid.h"

#include <algorithm>

namespace cvslam::vision {

std::vector<cv::KeyPoint> retainUniform(const std::vector<cv::KeyPoint>& keypoints,
                                        cv::Size image_size, int max_keypoints, int cols,
                                        int rows) {
  if (static_cast<int>(keypoints.size()) <= max_keypoints || cols <= 0 || rows <= 0 ||
      image_size.width <= 0 || image_size.height <= 0)
    return keypoints;
  std::vector<std::vector<int>> cells(static_cast<std::size_t>(cols * rows));
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const cv::Point2f& p = keypoints[i].pt;
    const int cx = std::clamp(static_cast<int>(p.x * cols / image_size.width), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y * rows / image_size.height), 0, rows - 1);
    cells[static_cast<std::size_t>(cy * cols + cx)].push_back(static_cast<int>(i));
  }
  auto stronger = [&](int a, int b) {
    const cv::KeyPoint& ka = keypoints[static_cast<std::size_t>(a)];
    const cv::KeyPoint& kb = keypoints[static_cast<std::size_t>(b)];
    if (ka.response != kb.response) return ka.response > kb.response;
    if (ka.pt.y != kb.pt.y) return ka.pt.y < kb.pt.y;
    return ka.pt.x < kb.pt.x;
  };
  for (auto& c : cells) std::sort(c.begin(), c.end(), stronger);
  std::vector<cv::KeyPoint> out;
  out.reserve(static_cast<std::size_t>(max_keypoints));
  for (std::size_t rank = 0; static_cast<int>(out.size()) < max_keypoints; ++rank) {
    bool any = false;
    for (const auto& c : cells) {
      if (rank >= c.size()) continue;
      any = true;
      out.push_back(keypoints[static_cast<std::size_t>(c[rank])]);
      if (static_cast<int>(out.size()) >= max_keypoints) break;
    }
    if (!any) break;
  }
  return out;
}

}  // namespace cvslam::vision
