#pragma once
// Orientation and the 128-byte SIFT descriptor (Lowe 2004; thesis §4.2.4) of keypoints of a
// SiftScaleSpace, computed only for the keypoints the caller keeps. The layout and scaling are
// OpenCV's (4×4 cells × 8 orientations, trilinear votes, Gaussian window of half the width,
// clipped at 0.2, normalised to 512 and saturated to bytes), so the descriptors compare with
// the same distances and gates and map to the same visual words (config/vocabulary_sift.cvoc)
// as adaptive SIFT's. One orientation per keypoint (the dominant one): OpenCV's extra keypoints
// for secondary peaks are the same image point again (docs/front_end.md, duplicates).

#include <opencv2/core.hpp>
#include <vector>

#include "cvslam/vision/sift_scale_space.h"

namespace cvslam::vision {

/// Computes SIFT descriptors with reusable scratch buffers (no allocation per keypoint).
class SiftDescriber {
 public:
  /// Assigns each keypoint its dominant orientation (kp.angle, degrees, OpenCV's convention)
  /// and writes one 128-byte row per keypoint into `descriptors` (CV_8U).
  void describe(const SiftScaleSpace& space, std::vector<cv::KeyPoint>* keypoints,
                cv::Mat* descriptors);

 private:
  float orientation(const cv::Mat& img, cv::Point pt, float sigma);  // sigma: keypoint σ
  void descriptor(const cv::Mat& img, cv::Point2f pt, float angle, float scale, uint8_t* out);

  void reserve(std::size_t n);  // scratch for n window samples

  std::vector<float> dx_, dy_, w_, rbin_, cbin_, angle_, mag_;
  std::vector<float> row_weight_;
  std::vector<float> hist_;
};

}  // namespace cvslam::vision
