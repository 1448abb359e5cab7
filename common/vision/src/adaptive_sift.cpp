#include "cvslam/vision/adaptive_sift.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

Status AdaptiveSiftOptions::load(const ConfigNode& node) {
  node.get("sigma0", sigma0);
  node.get("energy_low", energy_low);
  node.get("energy_high", energy_high);
  node.get("sigma_max", sigma_max);
  node.get("max_octave_layers", max_octave_layers);
  node.get("contrast_gain", contrast_gain);
  node.get("min_contrast", min_contrast);
  node.get("edge_threshold", edge_threshold);
  node.get("min_features", min_features);
  node.get("max_features", max_features);
  node.get("retries", retries);
  node.get("upsample_first_octave", upsample_first_octave);
  node.check(sigma0 > 0, "sigma0", "must be > 0");
  node.check(energy_low > 0 && energy_high > energy_low, "energy_high",
             "need 0 < energy_low < energy_high");
  node.check(sigma_max > sigma0, "sigma_max", "must be > sigma0");
  node.check(max_octave_layers >= 1 && max_octave_layers <= 12, "max_octave_layers",
             "must be in [1, 12]");
  node.check(contrast_gain > 0 && min_contrast >= 0, "contrast_gain", "must be > 0");
  node.check(min_features >= 0 && max_features > min_features, "max_features",
             "need 0 <= min_features < max_features");
  node.check(retries >= 0, "retries", "must be >= 0");
  return node.status();
}

double dogEnergy(const cv::Mat& gray, double sigma0, double k) {
  cv::Mat f;
  gray.convertTo(f, CV_32F);
  cv::Mat g0;
  cv::Mat g1;
  cv::GaussianBlur(f, g0, cv::Size(), sigma0, sigma0, cv::BORDER_REFLECT_101);
  cv::GaussianBlur(f, g1, cv::Size(), sigma0 * k, sigma0 * k, cv::BORDER_REFLECT_101);
  cv::Mat d = g1 - g0;
  return d.dot(d) / static_cast<double>(d.total());  // eq. 4.5 / (n·m)
}

ScaleFactorChoice adaptScaleFactor(const cv::Mat& gray, const AdaptiveSiftOptions& o) {
  ScaleFactorChoice c;
  // Energy is measured on a half-resolution copy when the image is large: it is a global
  // texture statistic and the blur at σ0·k grows with k (cost, not accuracy).
  cv::Mat img = gray;
  double scale = 1.0;
  if (gray.cols > 400) {
    cv::resize(gray, img, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    scale = 0.5;
  }
  const double s0 = std::max(0.5, o.sigma0 * scale);
  double k = std::pow(2.0, 1.0 / 3.0);  // Lowe's k0
  double e = dogEnergy(img, s0, k);
  c.energy0 = e;
  const double k_min = std::pow(2.0, 1.0 / o.max_octave_layers);
  // eq. 4.6, repeated until the energy is inside [S1, S2] or a scale limit is reached.
  while (e < o.energy_low && o.sigma0 * k * k <= o.sigma_max) {
    k = k * k;
    e = dogEnergy(img, s0, k);
  }
  while (e > o.energy_high && std::sqrt(k) >= k_min) {
    k = std::sqrt(k);
    e = dogEnergy(img, s0, k);
  }
  c.k = k;
  c.energy = e;
  c.octave_layers =
      std::clamp(static_cast<int>(std::lround(1.0 / std::log2(k))), 1, o.max_octave_layers);
  return c;
}

namespace {

// OpenCV's SIFT always doubles its input before the first octave. For a pyramid that starts
// at the input resolution it is given a 2× area-downsampled copy: the doubled copy then lies on
// the input's pixel grid (upsampled pixel x ≡ input pixel x) and, with the 2×2 box (σ ≈ 0.58
// px), the linear upsampling (σ ≈ 0.41 px) and OpenCV's base blur √(σ0² − 1) on top of the
// input's assumed 0.5 px, its base blur is ≈ 1.5 px ≈ σ0: close to Lowe's first octave at
// the input resolution. Odd last rows/columns are dropped (one pixel, no keypoint lives there).
cv::Mat halfResolution(const cv::Mat& gray) {
  const cv::Rect even(0, 0, gray.cols & ~1, gray.rows & ~1);
  cv::Mat half;
  cv::resize(gray(even), half, cv::Size(even.width / 2, even.height / 2), 0, 0, cv::INTER_AREA);
  return half;
}

// Keypoints of the half-resolution copy back to the input: OpenCV reports a doubled-octave
// keypoint at half its upsampled coordinate, so the input coordinate is 2·pt exactly; the
// packed octave (low byte, signed) is one higher.
void toInputResolution(std::vector<cv::KeyPoint>* keypoints) {
  for (cv::KeyPoint& kp : *keypoints) {
    kp.pt *= 2.0f;
    kp.size *= 2.0f;
    const int octave = static_cast<int8_t>(kp.octave & 0xFF);
    kp.octave = (kp.octave & ~0xFF) | ((octave + 1) & 0xFF);
  }
}

}  // namespace

Status detectAdaptiveSift(const cv::Mat& gray, const AdaptiveSiftOptions& o, Features* out,
                          ScaleFactorChoice* choice) {
  if (gray.empty() || gray.type() != CV_8UC1)
    return Status::Error("adaptive SIFT: expected a non-empty 8-bit grey image");
  const ScaleFactorChoice c = adaptScaleFactor(gray, o);
  if (choice) *choice = c;
  const bool half = !o.upsample_first_octave && gray.cols >= 2 && gray.rows >= 2;
  const cv::Mat input = half ? halfResolution(gray) : gray;
  // DoG threshold in grey levels, relative to the DoG energy at the adapted k. The DoG of
  // OpenCV's pyramid (levels k apart) has the same energy scale E(k); OpenCV applies
  // contrastThreshold·255/nOctaveLayers as the DoG threshold, hence the conversion.
  double dog_threshold = std::max(o.min_contrast, o.contrast_gain * std::sqrt(c.energy));
  out->type = DescriptorType::kSift;
  for (int attempt = 0;; ++attempt) {
    const double contrast = dog_threshold * c.octave_layers / 255.0;
    cv::Ptr<cv::SIFT> sift = cv::SIFT::create(o.max_features, c.octave_layers, contrast,
                                              o.edge_threshold, o.sigma0, CV_8U);
    out->keypoints.clear();
    sift->detectAndCompute(input, cv::noArray(), out->keypoints, out->descriptors);
    if (static_cast<int>(out->keypoints.size()) >= o.min_features || attempt >= o.retries ||
        dog_threshold <= o.min_contrast)
      break;
    dog_threshold = std::max(o.min_contrast, 0.5 * dog_threshold);
  }
  if (half) toInputResolution(&out->keypoints);
  // OpenCV's nfeatures keeps ties, so the count can exceed the cap by a few.
  if (static_cast<int>(out->keypoints.size()) > o.max_features) {
    out->keypoints.resize(static_cast<std::size_t>(o.max_features));
    out->descriptors = out->descriptors.rowRange(0, o.max_features).clone();
  }
  return Status::Ok();
}

}  // namespace cvslam::vision
