#include "cvslam/vision/sift_descriptor.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <opencv2/core/hal/hal.hpp>

namespace cvslam::vision {

namespace {

constexpr int kWidth = 4;  // d: 4×4 spatial cells
constexpr int kBins = 8;   // n: orientation bins per cell
constexpr int kDescriptorBytes = kWidth * kWidth * kBins;
constexpr float kCellScale = 3.0f;      // cell width = 3σ (Lowe)
constexpr float kMagnitudeClip = 0.2f;  // illumination: clip large gradients (Lowe)
constexpr float kByteScale = 512.0f;    // OpenCV's integer descriptor scale
constexpr int kOrientationBins = 36;
constexpr float kOrientationSigma = 1.5f;  // window σ = 1.5 × keypoint σ (Lowe)
constexpr float kOrientationRadius = 3.0f * kOrientationSigma;
constexpr float kDegPerRad = 57.29577951308232f;

// Cells out of the padded histogram, clipped at 0.2 of the norm, scaled to 512 and saturated
// to bytes (Lowe; OpenCV's integer descriptor).
void normalise(float* hist, uint8_t* out) {
  float dst[kDescriptorBytes];
  for (int i = 0; i < kWidth; ++i)
    for (int j = 0; j < kWidth; ++j) {
      const int idx = ((i + 1) * (kWidth + 2) + (j + 1)) * (kBins + 2);
      hist[idx] += hist[idx + kBins];  // orientation wrap-around
      hist[idx + 1] += hist[idx + kBins + 1];
      for (int k = 0; k < kBins; ++k) dst[(i * kWidth + j) * kBins + k] = hist[idx + k];
    }
  float nrm2 = 0;
  for (float v : dst) nrm2 += v * v;
  const float thr = std::sqrt(nrm2) * kMagnitudeClip;
  nrm2 = 0;
  for (float& v : dst) {
    v = std::min(v, thr);
    nrm2 += v * v;
  }
  const float s = kByteScale / std::max(std::sqrt(nrm2), FLT_EPSILON);
  for (int k = 0; k < kDescriptorBytes; ++k) out[k] = cv::saturate_cast<uint8_t>(dst[k] * s);
}

}  // namespace

float SiftDescriber::orientation(const cv::Mat& img, cv::Point pt, float sigma) {
  const int radius = cvRound(kOrientationRadius * sigma);
  const float window = kOrientationSigma * sigma;
  const float exp_scale = -1.0f / (2.0f * window * window);
  const std::size_t side = static_cast<std::size_t>(2 * radius + 1);
  row_weight_.resize(side);
  for (int i = -radius; i <= radius; ++i)  // exp(−(i² + j²)/2σ²) = w(i)·w(j)
    row_weight_[static_cast<std::size_t>(i + radius)] =
        std::exp(static_cast<float>(i * i) * exp_scale);
  reserve(side * side);
  const float* w = row_weight_.data() + radius;
  const int j0 = std::max(-radius, 1 - pt.x), j1 = std::min(radius, img.cols - 2 - pt.x);
  std::size_t len = 0;
  for (int i = -radius; i <= radius; ++i) {
    const int y = pt.y + i;
    if (y <= 0 || y >= img.rows - 1 || j1 < j0) continue;
    const float* row = img.ptr<float>(y) + pt.x;
    const float* up = img.ptr<float>(y - 1) + pt.x;
    const float* down = img.ptr<float>(y + 1) + pt.x;
    float* dx = dx_.data() + len - j0;
    float* dy = dy_.data() + len - j0;
    float* wt = w_.data() + len - j0;
    for (int j = j0; j <= j1; ++j) {  // vectorises
      dx[j] = row[j + 1] - row[j - 1];
      dy[j] = up[j] - down[j];
      wt[j] = w[i] * w[j];
    }
    len += static_cast<std::size_t>(j1 - j0 + 1);
  }
  const int n = static_cast<int>(len);
  cv::hal::fastAtan2(dy_.data(), dx_.data(), angle_.data(), n, true);  // OpenCV's SIMD kernels
  cv::hal::magnitude32f(dx_.data(), dy_.data(), mag_.data(), n);
  float raw[kOrientationBins] = {};
  for (std::size_t k = 0; k < len; ++k) {
    int bin = cvRound(angle_[k] * (kOrientationBins / 360.0f));
    bin = bin >= kOrientationBins ? bin - kOrientationBins : bin;
    raw[bin] += w_[k] * mag_[k];
  }
  // [1 4 6 4 1]/16 circular smoothing, then the highest peak, parabola-interpolated.
  float hist[kOrientationBins];
  auto at = [&raw](int b) { return raw[(b + kOrientationBins) % kOrientationBins]; };
  for (int b = 0; b < kOrientationBins; ++b)
    hist[b] = (at(b - 2) + at(b + 2)) * (1.0f / 16) + (at(b - 1) + at(b + 1)) * (4.0f / 16) +
              at(b) * (6.0f / 16);
  const int peak = static_cast<int>(std::max_element(hist, hist + kOrientationBins) - hist);
  const float l = hist[(peak + kOrientationBins - 1) % kOrientationBins];
  const float r = hist[(peak + 1) % kOrientationBins];
  const float denom = l - 2.0f * hist[peak] + r;
  float bin = peak + (denom != 0.0f ? 0.5f * (l - r) / denom : 0.0f);
  bin = bin < 0 ? bin + kOrientationBins : bin >= kOrientationBins ? bin - kOrientationBins : bin;
  float angle = 360.0f - (360.0f / kOrientationBins) * bin;
  if (std::abs(angle - 360.0f) < FLT_EPSILON) angle = 0.0f;
  return angle;
}

// OpenCV's calcSIFTDescriptor (sift.simd.hpp) restructured for speed, same result: the rows'
// column ranges inside the rotated 4×4-cell square are solved for (no per-pixel rejection),
// the Gaussian weight is factored by rows and columns (it depends on i² + j² only), and the
// gradients are collected first so that angles and magnitudes are one vectorisable loop.
void SiftDescriber::descriptor(const cv::Mat& img, cv::Point2f ptf, float ori, float scl,
                               uint8_t* out) {
  const cv::Point pt(cvRound(ptf.x), cvRound(ptf.y));
  const float hist_width = kCellScale * scl;
  int radius = cvRound(hist_width * 1.4142135623730951f * (kWidth + 1) * 0.5f);
  radius = std::min(radius, static_cast<int>(std::hypot(img.cols, img.rows)));
  const float cos_t = std::cos(ori / kDegPerRad) / hist_width;
  const float sin_t = std::sin(ori / kDegPerRad) / hist_width;
  const float exp_scale = -1.0f / (kWidth * kWidth * 0.5f * hist_width * hist_width);
  const std::size_t side = static_cast<std::size_t>(2 * radius + 1);
  row_weight_.resize(side);
  for (int i = -radius; i <= radius; ++i)
    row_weight_[static_cast<std::size_t>(i + radius)] =
        std::exp(static_cast<float>(i * i) * exp_scale);
  reserve(side * side);
  constexpr float kBinOffset = kWidth / 2 - 0.5f;
  const float kLastBin = std::nextafter(static_cast<float>(kWidth), 0.0f);
  std::size_t len = 0;
  for (int i = -radius; i <= radius; ++i) {
    const int r = pt.y + i;
    if (r <= 0 || r >= img.rows - 1) continue;
    // Columns j with rbin = j·sin + i·cos + off and cbin = j·cos − i·sin + off in (−1, d),
    // widened by a pixel (the samples outside get weight 0 below).
    float jlo = static_cast<float>(-radius), jhi = static_cast<float>(radius);
    auto limit = [&](float a, float b) {  // −1 < a·j + b < d
      if (std::abs(a) < 1e-12f) {
        if (!(b > -1 && b < kWidth)) jhi = jlo - 1;
        return;
      }
      const float x0 = (-1 - b) / a, x1 = (kWidth - b) / a;
      jlo = std::max(jlo, std::min(x0, x1) - 1);
      jhi = std::min(jhi, std::max(x0, x1) + 1);
    };
    limit(sin_t, i * cos_t + kBinOffset);
    limit(cos_t, -i * sin_t + kBinOffset);
    const int j0 = std::max(static_cast<int>(std::ceil(jlo)), 1 - pt.x);
    const int j1 = std::min(static_cast<int>(std::floor(jhi)), img.cols - 2 - pt.x);
    if (j1 < j0) continue;
    const float* row = img.ptr<float>(r) + pt.x;
    const float* up = img.ptr<float>(r - 1) + pt.x;
    const float* down = img.ptr<float>(r + 1) + pt.x;
    const float wi = row_weight_[static_cast<std::size_t>(i + radius)];
    const float* wj = row_weight_.data() + radius;
    float* dx = dx_.data() + len - j0;
    float* dy = dy_.data() + len - j0;
    float* wt = w_.data() + len - j0;
    float* rb = rbin_.data() + len - j0;
    float* cb = cbin_.data() + len - j0;
    for (int j = j0; j <= j1; ++j) {  // branch-free: vectorises
      const float rbin = static_cast<float>(j) * sin_t + static_cast<float>(i) * cos_t + kBinOffset;
      const float cbin = static_cast<float>(j) * cos_t - static_cast<float>(i) * sin_t + kBinOffset;
      float inside = rbin > -1.0f ? 1.0f : 0.0f;  // selects, not branches
      inside = rbin < kWidth ? inside : 0.0f;
      inside = cbin > -1.0f ? inside : 0.0f;
      inside = cbin < kWidth ? inside : 0.0f;
      dx[j] = row[j + 1] - row[j - 1];
      dy[j] = up[j] - down[j];
      wt[j] = wi * wj[j] * inside;
      // Outside samples vote 0; their bins are clamped into the padded histogram (inside
      // values, in (−1, d), are left as they are).
      const float rlo = rbin < -1.0f ? -1.0f : rbin;
      const float clo = cbin < -1.0f ? -1.0f : cbin;
      rb[j] = rlo > kLastBin ? kLastBin : rlo;
      cb[j] = clo > kLastBin ? kLastBin : clo;
    }
    len += static_cast<std::size_t>(j1 - j0 + 1);
  }
  const int n = static_cast<int>(len);
  cv::hal::fastAtan2(dy_.data(), dx_.data(), angle_.data(), n, true);  // OpenCV's SIMD kernels
  cv::hal::magnitude32f(dx_.data(), dy_.data(), mag_.data(), n);
  const float bins_per_deg = kBins / 360.0f;
  float* obin_v = angle_.data();
  float* mag_v = mag_.data();
  for (std::size_t k = 0; k < len; ++k) {
    obin_v[k] = (obin_v[k] - ori) * bins_per_deg;
    mag_v[k] *= w_[k];
  }
  constexpr int kHistLen = (kWidth + 2) * (kWidth + 2) * (kBins + 2);
  hist_.assign(kHistLen, 0.0f);
  float* hist = hist_.data();
  for (std::size_t k = 0; k < len; ++k) {
    float rbin = rbin_[k], cbin = cbin_[k], obin = obin_v[k];
    const float mag = mag_v[k];
    // cvFloor, not truncation of a shifted value: rbin + 1 can round up to the next integer.
    const int r0 = cvFloor(rbin);
    const int c0 = cvFloor(cbin);
    int o0 = cvFloor(obin);
    rbin -= static_cast<float>(r0), cbin -= static_cast<float>(c0), obin -= static_cast<float>(o0);
    o0 = o0 < 0 ? o0 + kBins : o0 >= kBins ? o0 - kBins : o0;
    // Trilinear votes into the 8 neighbouring (row, column, orientation) bins.
    const float v_r1 = mag * rbin, v_r0 = mag - v_r1;
    const float v_rc11 = v_r1 * cbin, v_rc10 = v_r1 - v_rc11;
    const float v_rc01 = v_r0 * cbin, v_rc00 = v_r0 - v_rc01;
    const float v_rco111 = v_rc11 * obin, v_rco110 = v_rc11 - v_rco111;
    const float v_rco101 = v_rc10 * obin, v_rco100 = v_rc10 - v_rco101;
    const float v_rco011 = v_rc01 * obin, v_rco010 = v_rc01 - v_rco011;
    const float v_rco001 = v_rc00 * obin, v_rco000 = v_rc00 - v_rco001;
    float* h = hist + ((r0 + 1) * (kWidth + 2) + c0 + 1) * (kBins + 2) + o0;
    h[0] += v_rco000;
    h[1] += v_rco001;
    h[kBins + 2] += v_rco010;
    h[kBins + 3] += v_rco011;
    h[(kWidth + 2) * (kBins + 2)] += v_rco100;
    h[(kWidth + 2) * (kBins + 2) + 1] += v_rco101;
    h[(kWidth + 3) * (kBins + 2)] += v_rco110;
    h[(kWidth + 3) * (kBins + 2) + 1] += v_rco111;
  }
  normalise(hist, out);
}

void SiftDescriber::reserve(std::size_t n) {
  if (dx_.size() >= n) return;
  for (auto* v : {&dx_, &dy_, &w_, &rbin_, &cbin_, &angle_, &mag_}) v->resize(n);
}

void SiftDescriber::describe(const SiftScaleSpace& space, std::vector<cv::KeyPoint>* keypoints,
                             cv::Mat* descriptors) {
  descriptors->create(static_cast<int>(keypoints->size()), kDescriptorBytes, CV_8U);
  for (std::size_t i = 0; i < keypoints->size(); ++i) {
    cv::KeyPoint& kp = (*keypoints)[i];
    const int octave = kp.octave & 0xFF;
    const int layer = (kp.octave >> 8) & 0xFF;
    const cv::Mat& img = space.gaussian(octave, layer);
    // Keypoint σ in the octave's pixels.
    const float sigma = kp.size * 0.5f * space.baseScale() / static_cast<float>(1 << octave);
    const cv::Point2f pt = space.toOctave(octave, kp.pt);
    kp.angle = orientation(img, cv::Point(cvRound(pt.x), cvRound(pt.y)), sigma);
    float angle = 360.0f - kp.angle;
    if (std::abs(angle - 360.0f) < FLT_EPSILON) angle = 0.0f;
    descriptor(img, pt, angle, sigma, descriptors->ptr<uint8_t>(static_cast<int>(i)));
  }
}

}  // namespace cvslam::vision
