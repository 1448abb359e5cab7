#pragma once
// Stereo correspondence by searching the right image along the row (issue 15; thesis §4.2.8):
// on a rectified pair a left keypoint (u_L, v_L) can only appear on the right at
//   u_R = u_L − d,  min_disparity < d ≤ HD_max = f·b/z_min,  v_R ≈ v_L,
// so instead of detecting and describing the right image and matching descriptors, the left
// keypoint's grey patch is compared with every position of that window by zero-mean
// normalised cross-correlation (ZNCC: invariant to the gain and offset between the cameras).
// A match must be good (ZNCC ≥ min_zncc) and unique (the DistRatio idea of §4.2.6 on
// dissimilarities: 1 − best < uniqueness·(1 − second best), the second best taken at least two
// pixels away), and is refined to sub-pixel disparity and row by parabolas through the
// neighbouring scores. The cost is a few hundred multiply-adds per candidate position, against
// detecting and describing a whole second image.

#include <opencv2/core.hpp>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/vision/stereo_matcher.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct RowSearchOptions {
  int patch_radius = 5;        ///< (2r+1)² patch [px]
  double min_zncc = 0.85;      ///< accept a best score at or above this
  double uniqueness = 0.6;     ///< 1 − best < uniqueness·(1 − second best)
  double min_patch_std = 2.0;  ///< grey-level std of a patch; flatter ones are not compared

  Status load(const ConfigNode& node);
};

struct RowStereoMatch {
  int left = -1;       ///< index of the left keypoint
  cv::Point2f right;   ///< (u_R, v_R) [px]
  double score = 0.0;  ///< ZNCC of the match
};

/// Searches the right image for left keypoints; buffers are kept between calls.
class RowStereoSearch {
 public:
  /// `stereo` gives the disparity window (min_disparity_px, HD_max) and VD_max (the row is
  /// refined within ±min(VD_max, 0.5) px). Both images CV_8UC1 of the same size.
  void search(const cv::Mat& left, const cv::Mat& right, const std::vector<cv::KeyPoint>& keypoints,
              const StereoMatchOptions& stereo, const RowSearchOptions& options,
              std::vector<RowStereoMatch>* matches);

 private:
  bool searchOne(const cv::KeyPoint& kp, int dlo, int dhi, double vd_max, const RowSearchOptions& o,
                 RowStereoMatch* match);
  double zncc(int x, int y) const;  // left patch (prepared) against right patch at (x, y)

  cv::Mat left_f_, right_f_;
  std::vector<float> patch_;  // zero-mean left patch, (2r+1)²
  float patch_norm_ = 0.0f;   // its L2 norm
  float patch_mean_ = 0.0f;   // its mean grey level
  float min_var_ = 0.0f;      // n·min_patch_std²: flatter patches are not compared
  int radius_ = 0;
  std::vector<float> num_, sum_, sq_, score_;
};

}  // namespace cvslam::vision
