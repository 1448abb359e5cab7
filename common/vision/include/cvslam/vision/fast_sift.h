#pragma once
// Fast adaptive SIFT of our own (issue 15; thesis §4.2.4–4.2.5, docs/front_end.md): the same
// adaptive scale factor and energy-relative DoG threshold as adaptive SIFT (adaptive_sift.h,
// items 1, 2, 3 and 5), on our own scale space (sift_scale_space.h) that starts at the input
// resolution (large images: at a resampled base, max_base_side), with the best N keypoints
// kept over a grid before any orientation or descriptor is computed (sift_descriptor.h). Detection
// and description are separate calls so that a front end can describe only the keypoints it keeps
// (e.g. those with a stereo match).

#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/vision/adaptive_sift.h"
#include "cvslam/vision/features.h"
#include "cvslam/vision/sift_descriptor.h"
#include "cvslam/vision/sift_scale_space.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct FastSiftOptions {
  int grid_cols = 8;    ///< keep the best N over a cols × rows grid (keypoint_grid.h); 0 = off
  int grid_rows = 6;    ///< (as ORB's grid, detector options)
  int max_octaves = 6;  ///< octaves of the scale space (fewer on small images)
  /// The scale space starts at the input resampled so that its longer side is at most this
  /// (the scales a large image needs: the finest octave of a 752×480 image holds most of the
  /// detection cost); 0 = always the input resolution.
  int max_base_side = 512;
  /// The stereo front end describes at most this many of its matches per frame (0 = all, or
  /// the front end's max_observations when that is smaller): those in a priority region first
  /// (where the map predicts a landmark, stereo_front_end.h), then by ZNCC. A descriptor costs
  /// ≈ 22 µs, most of the front end's time; the others are neither described nor observed.
  int describe_budget = 0;

  /// Base pixels per input pixel for an image of `size` (max_base_side; ≤ 1).
  double baseScale(cv::Size size) const;

  Status load(const ConfigNode& node);
};

class FastSift {
 public:
  /// `adaptive` supplies σ0, S1/S2, the contrast gain, the edge test and the count band.
  FastSift(const AdaptiveSiftOptions& adaptive, const FastSiftOptions& options)
      : a_(adaptive), o_(options) {}

  /// Builds the scale space of `gray` (CV_8UC1) and keeps at most max_features localised DoG
  /// extrema (angle −1, no descriptors yet); below min_features the threshold is halved
  /// (at most `retries` times) on the same scale space.
  Status detect(const cv::Mat& gray, std::vector<cv::KeyPoint>* keypoints,
                ScaleFactorChoice* choice = nullptr);
  /// Orientation and descriptors of keypoints of the last detect() (any subset, in order).
  void describe(std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors);
  /// detect() then describe() into `out`.
  Status detectAndDescribe(const cv::Mat& gray, Features* out);

 private:
  AdaptiveSiftOptions a_;
  FastSiftOptions o_;
  SiftScaleSpace space_;
  SiftDescriber describer_;
  std::vector<cv::KeyPoint> all_;
};

}  // namespace cvslam::vision
