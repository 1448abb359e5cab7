#include "cvslam/vision/swif.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/keypoint_grid.h"

namespace cvslam::vision {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr int kMaxLevels = 8;             // 2^8 = 256: coarser levels of a VGA image are empty
constexpr int kMaxOrientationBins = 360;  // bin ≥ 1° (Table 4.1 explores 3°…90°)
constexpr float kDescriptorByteScale = 512.0f;  // unit-norm entries → bytes (as OpenCV's SIFT)
constexpr int kBorder = 1;                      // the 3 × 3 neighbourhood must be inside the image

// Adds weight w at fractional circular bin position b of an n-bin histogram (linear split).
inline void addCircular(float* hist, int n, float b, float w) {
  const int b0 = static_cast<int>(std::floor(b));
  const float a = b - static_cast<float>(b0);
  const int i0 = ((b0 % n) + n) % n;
  const int i1 = (i0 + 1) % n;
  hist[i0] += w * (1.0f - a);
  hist[i1] += w * a;
}

}  // namespace

Status SwifOptions::load(const ConfigNode& node) {
  node.get("levels", levels);
  node.get("orders", orders);
  node.get("threshold", threshold);
  node.get("max_features", max_features);
  node.get("grid_cols", grid_cols);
  node.get("grid_rows", grid_rows);
  node.get("window", window);
  node.get("orientation_bins", orientation_bins);
  node.get("orientation_sigma", orientation_sigma);
  node.get("descriptor_clip", descriptor_clip);
  node.check(levels >= 1 && levels <= kMaxLevels, "levels", "must be in 1…8");
  bool orders_ok = orders.size() >= 3;
  for (std::size_t i = 0; i < orders.size(); ++i) {
    orders_ok = orders_ok && orders[i] >= 1 && orders[i] <= kMaxDaubechiesOrder;
    if (i > 0) orders_ok = orders_ok && orders[i] > orders[i - 1];
  }
  node.check(orders_ok, "orders",
             "must list at least 3 increasing Daubechies orders in 1…10 (extrema need a scale "
             "above and below)");
  node.check(threshold > 0, "threshold", "must be > 0");
  node.check(max_features > 0, "max_features", "must be > 0");
  node.check(grid_cols >= 0 && grid_rows >= 0 && (grid_cols == 0) == (grid_rows == 0), "grid_cols",
             "grid must be 0 × 0 (off) or positive in both directions");
  node.check(window >= 4, "window", "must be >= 4");
  node.check(orientation_bins >= 4 && orientation_bins <= kMaxOrientationBins, "orientation_bins",
             "must be in 4…360");
  node.check(orientation_sigma > 0, "orientation_sigma", "must be > 0");
  node.check(descriptor_clip > 0 && descriptor_clip <= 1, "descriptor_clip", "must be in (0, 1]");
  return node.status();
}

Status Swif::detect(const cv::Mat& gray, std::vector<cv::KeyPoint>* keypoints) {
  if (gray.empty() || gray.type() != CV_8UC1)
    return Status::Error("SWIF: expected a non-empty 8-bit grey image");
  const int n_orders = static_cast<int>(o_.orders.size());
  approximation_.resize(static_cast<std::size_t>(o_.levels));
  gray.convertTo(approximation_[0], CV_32F);
  // Levels whose approximation is smaller than the description window are not built.
  int levels = 0;
  pyramid_.resize(static_cast<std::size_t>(o_.levels));
  for (int l = 0; l < o_.levels; ++l) {
    const cv::Mat& a = approximation_[static_cast<std::size_t>(l)];
    if (std::min(a.rows, a.cols) < o_.window) break;
    auto& scales = pyramid_[static_cast<std::size_t>(l)];
    scales.resize(static_cast<std::size_t>(n_orders));
    for (int s = 0; s < n_orders; ++s) {
      Scale& sc = scales[static_cast<std::size_t>(s)];
      // The next approximation from the first (shortest) wavelet: eq. 4.27 repeated on A.
      const bool next = s == 0 && l + 1 < o_.levels;
      waveletLevel(a, o_.orders[static_cast<std::size_t>(s)], next, &sc.wavelet);
      if (next) approximation_[static_cast<std::size_t>(l + 1)] = sc.wavelet.next;
      sc.response.create(a.size(), CV_32F);
      for (int y = 0; y < a.rows; ++y) {
        const float* h = sc.wavelet.horizontal.ptr<float>(y);
        const float* v = sc.wavelet.vertical.ptr<float>(y);
        const float* d = sc.wavelet.diagonal.ptr<float>(y);
        float* r = sc.response.ptr<float>(y);
        for (int x = 0; x < a.cols; ++x) r[x] = std::cbrt(std::fabs(h[x] * v[x] * d[x]));
      }
      cv::phase(sc.wavelet.horizontal, sc.wavelet.vertical, sc.angle);
      cv::magnitude(sc.wavelet.horizontal, sc.wavelet.vertical, sc.magnitude);
    }
    ++levels;
  }
  pyramid_.resize(static_cast<std::size_t>(levels));
  all_.clear();
  for (int l = 0; l < levels; ++l) findMaxima(l, &all_);
  if (o_.grid_cols > 0) {
    *keypoints = retainUniform(all_, gray.size(), o_.max_features, o_.grid_cols, o_.grid_rows);
  } else {
    *keypoints = all_;
    std::stable_sort(
        keypoints->begin(), keypoints->end(),
        [](const cv::KeyPoint& x, const cv::KeyPoint& y) { return x.response > y.response; });
    if (static_cast<int>(keypoints->size()) > o_.max_features)
      keypoints->resize(static_cast<std::size_t>(o_.max_features));
  }
  return Status::Ok();
}

void Swif::findMaxima(int level, std::vector<cv::KeyPoint>* out) const {
  const auto& scales = pyramid_[static_cast<std::size_t>(level)];
  const float th = static_cast<float>(o_.threshold);
  const float f = static_cast<float>(1 << level);  // level pixels → input pixels
  for (std::size_t s = 1; s + 1 < scales.size(); ++s) {
    const cv::Mat& r = scales[s].response;
    const int step = static_cast<int>(r.step1());
    for (int y = kBorder; y < r.rows - kBorder; ++y) {
      const float* row = r.ptr<float>(y);
      for (int x = kBorder; x < r.cols - kBorder; ++x) {
        const float v = row[x];
        if (v < th) continue;
        // 8 neighbours at this order, then 9 + 9 at the orders below and above (§4.4.3.2 ii);
        // most points fail within the first few comparisons.
        bool is_max = true;
        for (int dy = -1; dy <= 1 && is_max; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if ((dx != 0 || dy != 0) && row[dy * step + x + dx] >= v) {
              is_max = false;
              break;
            }
        for (std::size_t t : {s - 1, s + 1}) {
          if (!is_max) break;
          const float* other = scales[t].response.ptr<float>(y);
          for (int dy = -1; dy <= 1 && is_max; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              if (other[dy * step + x + dx] >= v) {
                is_max = false;
                break;
              }
        }
        if (!is_max) continue;
        // Sub-pixel position: vertex of the parabola through the 3 samples along x and y.
        auto offset = [](float m, float c, float p) {
          const float den = m - 2.0f * c + p;
          return den < 0.0f ? std::clamp(0.5f * (m - p) / den, -0.5f, 0.5f) : 0.0f;
        };
        const float ox = offset(row[x - 1], v, row[x + 1]);
        const float oy = offset(row[x - step], v, row[x + step]);
        cv::KeyPoint kp(
            cv::Point2f((static_cast<float>(x) + ox) * f, (static_cast<float>(y) + oy) * f),
            static_cast<float>(o_.window) * f, -1.0f, v, level, static_cast<int>(s));
        out->push_back(kp);
      }
    }
  }
}

void Swif::describe(std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) {
  descriptors->create(static_cast<int>(keypoints->size()), kSwifDescriptorBytes, CV_8U);
  for (std::size_t i = 0; i < keypoints->size(); ++i) {
    cv::KeyPoint& kp = (*keypoints)[i];
    kp.angle = describeOne(kp, descriptors->ptr<uint8_t>(static_cast<int>(i)));
  }
}

float Swif::describeOne(const cv::KeyPoint& kp, uint8_t* descriptor) const {
  const Scale& sc =
      pyramid_[static_cast<std::size_t>(kp.octave)][static_cast<std::size_t>(kp.class_id)];
  const float f = static_cast<float>(1 << kp.octave);
  const int cx = static_cast<int>(std::lround(kp.pt.x / f));
  const int cy = static_cast<int>(std::lround(kp.pt.y / f));
  const int radius = o_.window / 2;
  // §4.4.7.1 c: σ = 1.5 × the feature's scale; the scale is taken as half the window radius, so
  // that the orientation window reaches the edge of the description window at 1.33σ.
  const float sigma_o =
      static_cast<float>(o_.orientation_sigma) * 0.5f * static_cast<float>(radius);
  // §4.4.7.2: the descriptor's Gaussian spans the window (σ = its radius), as SIFT's.
  const float sigma_d = static_cast<float>(radius);
  const int nb = o_.orientation_bins;
  std::array<float, kMaxOrientationBins + 1> hist{};
  std::array<float, kSwifDescriptorBytes> desc{};
  const float to_bin = static_cast<float>(nb / kTwoPi);
  const float to_desc = static_cast<float>(kSwifDescriptorBytes / kTwoPi);
  const int y0 = std::max(0, cy - radius), y1 = std::min(sc.angle.rows - 1, cy + radius);
  const int x0 = std::max(0, cx - radius), x1 = std::min(sc.angle.cols - 1, cx + radius);
  const float r2max = static_cast<float>(radius * radius);
  // Pass 1 (§4.4.7.1 b–c): histogram of atan2(V, H) weighted by the norm N and a Gaussian,
  // over a disc (a square window would not rotate with the image).
  for (int y = y0; y <= y1; ++y) {
    const float* ang = sc.angle.ptr<float>(y);
    const float* mag = sc.magnitude.ptr<float>(y);
    const float ddy = static_cast<float>(y - cy);
    for (int x = x0; x <= x1; ++x) {
      const float ddx = static_cast<float>(x - cx);
      const float r2 = ddx * ddx + ddy * ddy;
      if (r2 > r2max) continue;
      addCircular(hist.data(), nb, ang[x] * to_bin,
                  mag[x] * std::exp(-r2 / (2 * sigma_o * sigma_o)));
    }
  }
  // Smooth circularly ([1 2 1]/4, twice), then the peak with parabolic interpolation.
  for (int pass = 0; pass < 2; ++pass) {
    const float first = hist[0];
    float prev = hist[static_cast<std::size_t>(nb - 1)];
    for (int i = 0; i < nb; ++i) {
      const float cur = hist[static_cast<std::size_t>(i)];
      const float next = i + 1 < nb ? hist[static_cast<std::size_t>(i + 1)] : first;
      hist[static_cast<std::size_t>(i)] = 0.25f * (prev + 2.0f * cur + next);
      prev = cur;
    }
  }
  int peak = 0;
  for (int i = 1; i < nb; ++i)
    if (hist[static_cast<std::size_t>(i)] > hist[static_cast<std::size_t>(peak)]) peak = i;
  const float hm = hist[static_cast<std::size_t>((peak + nb - 1) % nb)];
  const float hc = hist[static_cast<std::size_t>(peak)];
  const float hp = hist[static_cast<std::size_t>((peak + 1) % nb)];
  const float den = hm - 2.0f * hc + hp;
  const float frac = den < 0.0f ? 0.5f * (hm - hp) / den : 0.0f;
  const float theta = static_cast<float>(
      std::fmod((static_cast<float>(peak) + frac + static_cast<float>(nb)) / to_bin, kTwoPi));
  // Pass 2 (§4.4.7.1 d, §4.4.7.2): orientations relative to Θ_f, weighted by N and the
  // descriptor's Gaussian, into the 41 circular bins.
  for (int y = y0; y <= y1; ++y) {
    const float* ang = sc.angle.ptr<float>(y);
    const float* mag = sc.magnitude.ptr<float>(y);
    const float ddy = static_cast<float>(y - cy);
    for (int x = x0; x <= x1; ++x) {
      const float ddx = static_cast<float>(x - cx);
      const float r2 = ddx * ddx + ddy * ddy;
      if (r2 > r2max) continue;
      float rel = ang[x] - theta;
      if (rel < 0.0f) rel += static_cast<float>(kTwoPi);
      addCircular(desc.data(), kSwifDescriptorBytes, rel * to_desc,
                  mag[x] * std::exp(-r2 / (2 * sigma_d * sigma_d)));
    }
  }
  // L2-normalise (contrast invariance, §4.4.7.2), clip, renormalise, quantise to bytes.
  auto normalise = [&desc]() {
    float n2 = 0.0f;
    for (float v : desc) n2 += v * v;
    const float inv = n2 > 0.0f ? 1.0f / std::sqrt(n2) : 0.0f;
    for (float& v : desc) v *= inv;
  };
  normalise();
  for (float& v : desc) v = std::min(v, static_cast<float>(o_.descriptor_clip));
  normalise();
  for (int i = 0; i < kSwifDescriptorBytes; ++i)
    descriptor[i] =
        cv::saturate_cast<uint8_t>(desc[static_cast<std::size_t>(i)] * kDescriptorByteScale);
  return static_cast<float>(theta * 180.0 / M_PI);
}

Status Swif::detectAndDescribe(const cv::Mat& gray, Features* out) {
  out->type = DescriptorType::kSwif;
  if (Status s = detect(gray, &out->keypoints); !s.ok()) return s;
  describe(&out->keypoints, &out->descriptors);
  return Status::Ok();
}

}  // namespace cvslam::vision
