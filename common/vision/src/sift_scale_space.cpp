#include "cvslam/vision/sift_scale_space.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace cvslam::vision {

namespace {

constexpr double kInputBlur = 0.5;    // Lowe: the camera image is already blurred by 0.5 px
constexpr int kImageBorder = 5;       // no extrema this close to the border (Lowe, OpenCV)
constexpr int kMaxInterpolation = 5;  // steps of the quadratic fit before giving up
constexpr int kMinOctaveSide = 16;    // an octave smaller than this holds no usable extremum

}  // namespace

void SiftScaleSpace::build(const cv::Mat& gray, int layers, double sigma0, int octaves,
                           double base_scale) {
  layers_ = layers;
  sigma0_ = sigma0;
  cv::Mat input = gray;
  base_scale_ = 1.0f;
  if (base_scale < 1.0) {
    // Area means (OpenCV's INTER_AREA: base pixel x is centred on input (x + ½)/s − ½).
    const cv::Size size(std::max(1, static_cast<int>(std::lround(gray.cols * base_scale))),
                        std::max(1, static_cast<int>(std::lround(gray.rows * base_scale))));
    cv::resize(gray, base_input_, size, 0, 0, cv::INTER_AREA);
    input = base_input_;
    base_scale_ = static_cast<float>(size.width) / static_cast<float>(gray.cols);
  }
  const int side = std::min(input.cols, input.rows);
  octaves_ = 0;
  for (int s = side; s >= kMinOctaveSide && octaves_ < octaves; s /= 2) ++octaves_;
  const int per_octave = layers + 3;
  gauss_.resize(static_cast<std::size_t>(octaves_ * per_octave));
  dog_.resize(static_cast<std::size_t>(octaves_ * (layers + 2)));

  // Incremental blur from level i−1 to i: σ_i² − σ_{i−1}², σ_i = σ0·k^i (same in every octave).
  std::vector<double> step(static_cast<std::size_t>(per_octave));
  const double k = std::pow(2.0, 1.0 / layers);
  for (int i = 1; i < per_octave; ++i) {
    const double prev = sigma0 * std::pow(k, i - 1);
    step[static_cast<std::size_t>(i)] = std::sqrt((prev * k) * (prev * k) - prev * prev);
  }
  cv::Mat base;
  input.convertTo(base, CV_32F);
  const double first = std::sqrt(std::max(sigma0 * sigma0 - kInputBlur * kInputBlur, 0.01));
  cv::GaussianBlur(base, gauss_[0], cv::Size(), first, first, cv::BORDER_REFLECT_101);
  for (int o = 0; o < octaves_; ++o) {
    for (int i = 0; i < per_octave; ++i) {
      cv::Mat& dst = gauss_[static_cast<std::size_t>(o * per_octave + i)];
      if (o == 0 && i == 0) continue;
      if (i == 0) {
        // Level `layers` of the octave below has σ = 2σ0: every second pixel of it starts
        // this octave (Lowe).
        const cv::Mat& src = gaussian(o - 1, layers);
        cv::resize(src, dst, cv::Size(src.cols / 2, src.rows / 2), 0, 0, cv::INTER_NEAREST);
      } else {
        const double s = step[static_cast<std::size_t>(i)];
        cv::GaussianBlur(gaussian(o, i - 1), dst, cv::Size(), s, s, cv::BORDER_REFLECT_101);
      }
    }
    for (int i = 0; i < layers + 2; ++i)
      cv::subtract(gaussian(o, i + 1), gaussian(o, i),
                   dog_[static_cast<std::size_t>(o * (layers + 2) + i)]);
  }
}

namespace {

// flags[c] = 1 where row[c] is beyond ±pre and a maximum (minimum) of its 3×3 neighbourhood
// in its own DoG image. Branch-free over the row, so it vectorises: the cheap filter before the
// 18 neighbours in the levels above and below (extremumAcrossLevels), which few samples reach.
void markPlaneExtrema(const float* row, int step, int cols, float pre, uint8_t* flags) {
  const float* up = row - step;
  const float* down = row + step;
  flags[0] = flags[cols - 1] = 0;
  for (int c = 1; c < cols - 1; ++c) {
    const float x = row[c];
    const float a = up[c - 1], b = up[c], d = up[c + 1], e = row[c - 1], g = row[c + 1];
    const float h = down[c - 1], i = down[c], j = down[c + 1];
    const bool is_max = (x > pre) & (x >= a) & (x >= b) & (x >= d) & (x >= e) & (x >= g) &
                        (x >= h) & (x >= i) & (x >= j);
    const bool is_min = (x < -pre) & (x <= a) & (x <= b) & (x <= d) & (x <= e) & (x <= g) &
                        (x <= h) & (x <= i) & (x <= j);
    flags[c] = static_cast<uint8_t>(is_max | is_min);
  }
}

// The 3×3 neighbourhoods in the DoG levels below and above (ties allowed, as OpenCV).
bool extremumAcrossLevels(const float* prev, const float* next, int step, float v) {
  const int off[9] = {-step - 1, -step, -step + 1, -1, 0, 1, step - 1, step, step + 1};
  if (v > 0) {
    for (int n : off)
      if (v < prev[n] || v < next[n]) return false;
    return true;
  }
  for (int n : off)
    if (v > prev[n] || v > next[n]) return false;
  return true;
}

struct Derivatives {
  cv::Vec3f g;    // ∂D/∂x, ∂D/∂y, ∂D/∂σ
  cv::Matx33f h;  // Hessian
};

Derivatives derivatives(const cv::Mat& prev, const cv::Mat& cur, const cv::Mat& next, int r,
                        int c) {
  auto at = [](const cv::Mat& m, int y, int x) { return m.at<float>(y, x); };
  Derivatives d;
  d.g = cv::Vec3f((at(cur, r, c + 1) - at(cur, r, c - 1)) * 0.5f,
                  (at(cur, r + 1, c) - at(cur, r - 1, c)) * 0.5f,
                  (at(next, r, c) - at(prev, r, c)) * 0.5f);
  const float v2 = 2.0f * at(cur, r, c);
  const float dxx = at(cur, r, c + 1) + at(cur, r, c - 1) - v2;
  const float dyy = at(cur, r + 1, c) + at(cur, r - 1, c) - v2;
  const float dss = at(next, r, c) + at(prev, r, c) - v2;
  const float dxy = (at(cur, r + 1, c + 1) - at(cur, r + 1, c - 1) - at(cur, r - 1, c + 1) +
                     at(cur, r - 1, c - 1)) *
                    0.25f;
  const float dxs =
      (at(next, r, c + 1) - at(next, r, c - 1) - at(prev, r, c + 1) + at(prev, r, c - 1)) * 0.25f;
  const float dys =
      (at(next, r + 1, c) - at(next, r - 1, c) - at(prev, r + 1, c) + at(prev, r - 1, c)) * 0.25f;
  d.h = cv::Matx33f(dxx, dxy, dxs, dxy, dyy, dys, dxs, dys, dss);
  return d;
}

// Lowe's localisation (§4 of his paper, as OpenCV's adjustLocalExtrema): Newton steps on the
// 3-D quadratic until the offset is below half a sample, then the contrast and edge tests.
bool localise(const SiftScaleSpace& s, int o, int layer, int r, int c, double threshold,
              double edge, cv::KeyPoint* kp) {
  const cv::Mat& d0 = s.dog(o, 0);
  cv::Vec3f x;
  Derivatives d;
  int step = 0;
  for (; step < kMaxInterpolation; ++step) {
    d = derivatives(s.dog(o, layer - 1), s.dog(o, layer), s.dog(o, layer + 1), r, c);
    x = -d.h.solve(d.g, cv::DECOMP_LU);  // fixed size: no allocation per extremum
    if (std::abs(x[0]) < 0.5f && std::abs(x[1]) < 0.5f && std::abs(x[2]) < 0.5f) break;
    if (std::abs(x[0]) > 1e6f || std::abs(x[1]) > 1e6f || std::abs(x[2]) > 1e6f) return false;
    c += static_cast<int>(std::lround(x[0]));
    r += static_cast<int>(std::lround(x[1]));
    layer += static_cast<int>(std::lround(x[2]));
    if (layer < 1 || layer > s.layers() || c < kImageBorder || c >= d0.cols - kImageBorder ||
        r < kImageBorder || r >= d0.rows - kImageBorder)
      return false;
  }
  if (step >= kMaxInterpolation) return false;
  const float contrast = s.dog(o, layer).at<float>(r, c) + 0.5f * d.g.dot(x);
  if (std::abs(contrast) < threshold) return false;
  const float tr = d.h(0, 0) + d.h(1, 1);
  const float det = d.h(0, 0) * d.h(1, 1) - d.h(0, 1) * d.h(0, 1);
  if (det <= 0 || tr * tr * edge >= (edge + 1) * (edge + 1) * det) return false;
  const double scale = static_cast<double>(1 << o) / s.baseScale();  // octave → input pixels
  kp->pt = s.toInput(o, cv::Point2f(static_cast<float>(c) + x[0], static_cast<float>(r) + x[1]));
  kp->octave = o + (layer << 8) + (static_cast<int>(std::lround((x[2] + 0.5) * 255)) << 16);
  kp->size = static_cast<float>(
      s.sigma0() * std::pow(2.0, (layer + x[2]) / static_cast<double>(s.layers())) * scale * 2.0);
  kp->response = std::abs(contrast);
  kp->angle = -1.0f;
  return true;
}

}  // namespace

void SiftScaleSpace::findExtrema(double dog_threshold, double edge_threshold,
                                 std::vector<cv::KeyPoint>* keypoints) {
  keypoints->clear();
  // Lowe's pre-test: a sample below half the threshold cannot interpolate above it.
  const float pre = static_cast<float>(0.5 * dog_threshold);
  for (int o = 0; o < octaves_; ++o) {
    for (int layer = 1; layer <= layers_; ++layer) {
      const cv::Mat& cur = dog(o, layer);
      const int cols = cur.cols;
      const int step = static_cast<int>(cur.step1());
      flags_.resize(static_cast<std::size_t>(cols));
      for (int r = kImageBorder; r < cur.rows - kImageBorder; ++r) {
        markPlaneExtrema(cur.ptr<float>(r), step, cols, pre, flags_.data());
        const float* prev = dog(o, layer - 1).ptr<float>(r);
        const float* next = dog(o, layer + 1).ptr<float>(r);
        for (int c = kImageBorder; c < cols - kImageBorder; ++c) {
          if (!flags_[static_cast<std::size_t>(c)]) continue;
          if (!extremumAcrossLevels(prev + c, next + c, step, cur.ptr<float>(r)[c])) continue;
          cv::KeyPoint kp;
          if (localise(*this, o, layer, r, c, dog_threshold, edge_threshold, &kp))
            keypoints->push_back(kp);
        }
      }
    }
  }
}

}  // namespace cvslam::vision
