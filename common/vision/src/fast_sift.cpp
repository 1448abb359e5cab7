#include "cvslam/vision/fast_sift.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/keypoint_grid.h"

namespace cvslam::vision {

Status FastSiftOptions::load(const ConfigNode& node) {
  node.get("grid_cols", grid_cols);
  node.get("grid_rows", grid_rows);
  node.get("max_octaves", max_octaves);
  node.get("max_base_side", max_base_side);
  node.get("describe_budget", describe_budget);
  node.check(grid_cols >= 0 && grid_rows >= 0 && (grid_cols == 0) == (grid_rows == 0), "grid_cols",
             "grid must be 0 × 0 (off) or positive in both directions");
  node.check(max_octaves >= 1, "max_octaves", "must be >= 1");
  node.check(max_base_side == 0 || max_base_side >= 64, "max_base_side", "must be 0 or >= 64");
  node.check(describe_budget >= 0, "describe_budget", "must be >= 0");
  return node.status();
}

double FastSiftOptions::baseScale(cv::Size size) const {
  const int side = std::max(size.width, size.height);
  return max_base_side > 0 && side > max_base_side ? static_cast<double>(max_base_side) / side
                                                   : 1.0;
}

Status FastSift::detect(const cv::Mat& gray, std::vector<cv::KeyPoint>* keypoints,
                        ScaleFactorChoice* choice) {
  if (gray.empty() || gray.type() != CV_8UC1)
    return Status::Error("fast SIFT: expected a non-empty 8-bit grey image");
  const ScaleFactorChoice c = adaptScaleFactor(gray, a_);
  if (choice) *choice = c;
  space_.build(gray, c.octave_layers, a_.sigma0, o_.max_octaves, o_.baseScale(gray.size()));
  // DoG threshold relative to the DoG energy at the adapted k (adaptive_sift.h, item 3).
  double dog_threshold = std::max(a_.min_contrast, a_.contrast_gain * std::sqrt(c.energy));
  for (int attempt = 0;; ++attempt) {
    space_.findExtrema(dog_threshold, a_.edge_threshold, &all_);
    if (static_cast<int>(all_.size()) >= a_.min_features || attempt >= a_.retries ||
        dog_threshold <= a_.min_contrast)
      break;
    dog_threshold = std::max(a_.min_contrast, 0.5 * dog_threshold);
  }
  if (o_.grid_cols > 0) {
    *keypoints = retainUniform(all_, gray.size(), a_.max_features, o_.grid_cols, o_.grid_rows);
  } else {
    *keypoints = all_;
    std::stable_sort(
        keypoints->begin(), keypoints->end(),
        [](const cv::KeyPoint& x, const cv::KeyPoint& y) { return x.response > y.response; });
    if (static_cast<int>(keypoints->size()) > a_.max_features)
      keypoints->resize(static_cast<std::size_t>(a_.max_features));
  }
  return Status::Ok();
}

void FastSift::describe(std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) {
  describer_.describe(space_, keypoints, descriptors);
}

Status FastSift::detectAndDescribe(const cv::Mat& gray, Features* out) {
  out->type = DescriptorType::kSift;
  if (Status s = detect(gray, &out->keypoints); !s.ok()) return s;
  describe(&out->keypoints, &out->descriptors);
  return Status::Ok();
}

}  // namespace cvslam::vision
