#include "cvslam/mosaic/super_resolution.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <limits>

#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {
namespace {

constexpr double kPeak = 255.0;  // 8-bit grey levels

// Low-pass mask of a DFT of size `size` (CV_32FC2 layout): keeps |f| ≤ bandwidth·Nyquist
// per axis (frequency index k and size − k are the same magnitude).
cv::Mat lowPassMask(cv::Size size, double bandwidth) {
  cv::Mat mask(size, CV_32FC2, cv::Scalar(0, 0));
  const double kx = bandwidth * size.width / 2.0, ky = bandwidth * size.height / 2.0;
  for (int r = 0; r < size.height; ++r) {
    const int fr = std::min(r, size.height - r);
    if (fr > ky) continue;
    for (int c = 0; c < size.width; ++c)
      if (std::min(c, size.width - c) <= kx) mask.at<cv::Vec2f>(r, c) = cv::Vec2f(1, 1);
  }
  return mask;
}

}  // namespace

Status SuperResolutionOptions::load(const ConfigNode& node) {
  node.get("scale", scale);
  node.get("iterations", iterations);
  node.get("bandwidth", bandwidth);
  node.get("padding", padding);
  node.check(scale >= 1, "scale", "must be ≥ 1");
  node.check(iterations >= 0, "iterations", "must be ≥ 0");
  node.check(bandwidth > 0.0 && bandwidth <= 1.0, "bandwidth", "must be in (0, 1]");
  node.check(padding >= 0, "padding", "must be ≥ 0");
  return node.status();
}

void projectOntoGrid(const std::vector<LowResFrame>& frames, cv::Size hr_size, cv::Mat* values,
                     cv::Mat* known) {
  cv::Mat sum(hr_size, CV_32F, cv::Scalar(0)), count(hr_size, CV_32F, cv::Scalar(0));
  for (const LowResFrame& f : frames) {
    cv::Mat img;
    f.image.convertTo(img, CV_32F);
    for (int v = 0; v < img.rows; ++v)
      for (int u = 0; u < img.cols; ++u) {
        const Eigen::Vector3d p = f.H_to_hr * Eigen::Vector3d(u, v, 1.0);
        // Nearest HR grid location of the magnified position (§4.3.4.2).
        const int c = static_cast<int>(std::lround(p.x() / p.z()));
        const int r = static_cast<int>(std::lround(p.y() / p.z()));
        if (c < 0 || r < 0 || c >= hr_size.width || r >= hr_size.height) continue;
        sum.at<float>(r, c) += img.at<float>(v, u);
        count.at<float>(r, c) += 1.0f;
      }
  }
  cv::Mat avg;
  cv::divide(sum, cv::max(count, 1.0f), avg);
  *values = avg;
  *known = count > 0.0f;
}

Expected<cv::Mat> papoulisGerchberg(const std::vector<LowResFrame>& frames, cv::Size hr_size,
                                    const SuperResolutionOptions& o, const cv::Mat& initial) {
  if (hr_size.width <= 0 || hr_size.height <= 0)
    return Status::Error("super-resolution: empty grid");
  if (!initial.empty() && initial.size() != hr_size)
    return Status::Error("super-resolution: initial image has the wrong size");
  cv::Mat values, known;
  projectOntoGrid(frames, hr_size, &values, &known);
  if (cv::countNonZero(known) == 0) return Status::Error("super-resolution: no LR pixel on grid");
  cv::Mat x;
  if (!initial.empty()) {
    initial.convertTo(x, CV_32F);
  } else {
    x = cv::Mat(hr_size, CV_32F, cv::mean(values, known));
  }
  values.copyTo(x, known);
  const int pad = o.padding;
  const cv::Rect inner(pad, pad, hr_size.width, hr_size.height);
  cv::Mat padded;
  cv::copyMakeBorder(x, padded, pad, pad, pad, pad, cv::BORDER_REFLECT);
  const cv::Mat mask = lowPassMask(padded.size(), o.bandwidth);
  cv::Mat spectrum;
  for (int it = 0; it < o.iterations; ++it) {
    // Step 2: band-limit in the frequency domain.
    cv::dft(padded, spectrum, cv::DFT_COMPLEX_OUTPUT);
    cv::multiply(spectrum, mask, spectrum);
    cv::idft(spectrum, padded, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
    // Step 3: force the known pixels; the padding is re-reflected from the interior.
    cv::Mat centre = padded(inner).clone();
    values.copyTo(centre, known);
    cv::copyMakeBorder(centre, padded, pad, pad, pad, pad, cv::BORDER_REFLECT);
  }
  return cv::Mat(padded(inner).clone());
}

double psnr(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& mask) {
  cv::Mat a, b;
  image.convertTo(a, CV_64F);
  truth.convertTo(b, CV_64F);
  cv::Mat d = a - b;
  d = d.mul(d);
  const double n = mask.empty() ? static_cast<double>(d.total()) : cv::countNonZero(mask);
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  if (!mask.empty()) d.setTo(0.0, mask == 0);
  const double mse = cv::sum(d)[0] / n;
  return 10.0 * std::log10(kPeak * kPeak / std::max(mse, 1e-12));
}

}  // namespace cvslam::mosaic
