#include "cvslam/vision/stereo_matcher.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

Status StereoMatchOptions::check() const {
  if (!(focal_px > 0) || !(baseline_m > 0) || !(min_depth_m > 0))
    return Status::Error("stereo matching: focal_px, baseline_m and min_depth_m must be > 0");
  if (max_vertical_disparity_px < 0 || min_disparity_px < 0)
    return Status::Error("stereo matching: disparity bounds must be >= 0");
  return Status::Ok();
}

Status StereoMatchOptions::load(const ConfigNode& node) {
  node.get("focal_px", focal_px);
  node.get("baseline_m", baseline_m);
  node.get("min_depth_m", min_depth_m);
  node.get("max_vertical_disparity_px", max_vertical_disparity_px);
  node.get("min_disparity_px", min_disparity_px);
  node.get("scale_rate_tolerance_log2", scale_rate_tolerance_log2);
  match.load(node.child("match"));
  node.check(focal_px >= 0, "focal_px", "must be >= 0 (0: taken from the calibration)");
  node.check(baseline_m >= 0, "baseline_m", "must be >= 0 (0: taken from the calibration)");
  node.check(min_depth_m > 0, "min_depth_m", "must be > 0");
  node.check(max_vertical_disparity_px >= 0, "max_vertical_disparity_px", "must be >= 0");
  node.check(min_disparity_px >= 0, "min_disparity_px", "must be >= 0");
  return node.status();
}

std::vector<StereoMatch> matchStereo(const Features& left, const Features& right,
                                     const StereoMatchOptions& o) {
  std::vector<StereoMatch> out;
  if (left.size() == 0 || right.size() == 0) return out;
  const double hd_max = o.maxHorizontalDisparity();
  const double vd_max = o.max_vertical_disparity_px;
  // Right features sorted by row: the VD band is a contiguous range.
  std::vector<int> by_row(right.size());
  for (std::size_t j = 0; j < right.size(); ++j) by_row[j] = static_cast<int>(j);
  auto row = [&](int j) { return right.keypoints[static_cast<std::size_t>(j)].pt.y; };
  std::sort(by_row.begin(), by_row.end(), [&](int a, int b) { return row(a) < row(b); });
  std::vector<float> rows(by_row.size());
  for (std::size_t k = 0; k < by_row.size(); ++k) rows[k] = row(by_row[k]);

  const bool check_scale = o.scale_rate_tolerance_log2 > 0;
  std::vector<std::vector<int>> candidates(left.size());
  for (std::size_t i = 0; i < left.size(); ++i) {
    const cv::KeyPoint& kl = left.keypoints[i];
    auto lo = std::lower_bound(rows.begin(), rows.end(), static_cast<float>(kl.pt.y - vd_max));
    auto hi = std::upper_bound(rows.begin(), rows.end(), static_cast<float>(kl.pt.y + vd_max));
    for (auto it = lo; it != hi; ++it) {
      const int j = by_row[static_cast<std::size_t>(it - rows.begin())];
      const cv::KeyPoint& kr = right.keypoints[static_cast<std::size_t>(j)];
      const double d = kl.pt.x - kr.pt.x;  // eq. 4.9
      if (d <= o.min_disparity_px || d > hd_max) continue;
      if (check_scale && kl.size > 0 && kr.size > 0 &&
          std::abs(std::log2(kr.size / kl.size)) > o.scale_rate_tolerance_log2)
        continue;
      candidates[i].push_back(j);
    }
  }
  for (const Match& m : matchDescriptors(left, right, o.match, &candidates))
    out.push_back({m.query, m.train, m.distance});
  return out;
}

}  // namespace cvslam::vision
