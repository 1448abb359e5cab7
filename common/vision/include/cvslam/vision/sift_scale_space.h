#pragma once
// The SIFT scale space of our own fast SIFT (thesis §4.2.4–4.2.5, Lowe 2004): a Gaussian
// pyramid and its difference-of-Gaussian (DoG) images, built from the input resolution (no
// doubled first octave), with the levels per octave the adaptive scale factor k asks for
// (eq. 4.6: levels = round(1/log2 k)), and the DoG extrema localised as Lowe does (3-D
// quadratic fit, contrast and edge tests).
//
// Why not OpenCV's SIFT: it always doubles the image (the first octave is ≈ 3/4 of its
// pyramid and extremum search) and computes orientations and descriptors before any selection;
// here the pyramid starts at the input resolution, the extrema are only localised, and the
// caller keeps the best N (grid-bucketed) before describing (sift_descriptor.h). The buffers
// are kept between images (no allocation per frame once sizes are stable).

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace cvslam::vision {

/// Gaussian and DoG pyramid of one grey image (float, grey levels 0..255).
class SiftScaleSpace {
 public:
  /// Builds `octaves` octaves (fewer if the image gets smaller than 16 px) of `layers` + 3
  /// Gaussian images each, the first at σ0 = `sigma0` on the base image: the input, or for
  /// `base_scale` < 1 the input resampled by that factor (area means). The base is taken to
  /// be blurred by 0.5 px (Lowe's assumption).
  void build(const cv::Mat& gray, int layers, double sigma0, int octaves, double base_scale = 1.0);

  int octaves() const { return octaves_; }
  /// Base pixels per input pixel (≤ 1).
  float baseScale() const { return base_scale_; }
  /// Input pixel coordinates of point `p` of `octave` (pixel centres are integers on both).
  cv::Point2f toInput(int octave, cv::Point2f p) const {
    const float o = static_cast<float>(1 << octave);
    return cv::Point2f((p.x * o + 0.5f) / base_scale_ - 0.5f,
                       (p.y * o + 0.5f) / base_scale_ - 0.5f);
  }
  /// The inverse of toInput().
  cv::Point2f toOctave(int octave, cv::Point2f p) const {
    const float o = static_cast<float>(1 << octave);
    return cv::Point2f(((p.x + 0.5f) * base_scale_ - 0.5f) / o,
                       ((p.y + 0.5f) * base_scale_ - 0.5f) / o);
  }
  int layers() const { return layers_; }
  double sigma0() const { return sigma0_; }
  /// Gaussian image `level` (0 .. layers + 2) of `octave`.
  const cv::Mat& gaussian(int octave, int level) const {
    return gauss_[static_cast<std::size_t>(octave * (layers_ + 3) + level)];
  }
  /// DoG image `level` (0 .. layers + 1) of `octave`: gaussian(level + 1) − gaussian(level).
  const cv::Mat& dog(int octave, int level) const {
    return dog_[static_cast<std::size_t>(octave * (layers_ + 2) + level)];
  }
  /// Localised DoG extrema with |D(x̂)| ≥ `dog_threshold` grey levels and a principal-curvature
  /// ratio below `edge_threshold` (Lowe's r). Keypoints are in input pixels (size too), with
  /// OpenCV's packing of the scale-space octave o (= OpenCV's when base_scale = 1):
  /// octave = o + (level << 8) + (round((ξ + 0.5)·255) << 16), size = 2σ, response = |D(x̂)|,
  /// angle = −1 (not yet assigned).
  void findExtrema(double dog_threshold, double edge_threshold,
                   std::vector<cv::KeyPoint>* keypoints);

 private:
  int octaves_ = 0;
  float base_scale_ = 1.0f;
  int layers_ = 0;
  double sigma0_ = 1.6;
  cv::Mat base_input_;  // the resampled input (base_scale < 1)
  std::vector<cv::Mat> gauss_;
  std::vector<cv::Mat> dog_;
  std::vector<uint8_t> flags_;  // extremum flags of one row (scratch)
};

}  // namespace cvslam::vision
