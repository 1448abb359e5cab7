#include "cvslam/vision/swif.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "cvslam/io/config_node.h"
#include "cvslam/vision/keypoint_grid.h"

namespace cvslam::vision {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr int kMaxLevels = 8;             // 2^8 = 256: coarser levels of a VGA image are empty
constexpr int kMaxOrientationBins = 360;  // bin ≥ 1° (Table 4.1 explores 3°…90°)
constexpr float kDescriptorByteScale = 512.0f;  // unit-norm entries → bytes (as OpenCV's SIFT)
constexpr int kMaxScalesPerOctave = 4;          // finer steps than 2^(1/4) only cost time
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

// Vertex of the parabola through (−1, m), (0, c), (1, p), in [−0.5, 0.5] (sub-pixel position).
inline float parabolaOffset(float m, float c, float p) {
  const float den = m - 2.0f * c + p;
  return den < 0.0f ? std::clamp(0.5f * (m - p) / den, -0.5f, 0.5f) : 0.0f;
}

/// Calls f(r², angle, magnitude) for every pixel of `scale` (its angle and magnitude images)
/// in the disc of `radius` around (cx, cy), clipped to the image: the sampling window of the
/// orientation and of the histogram descriptor (§4.4.7.1), which turns with the image.
template <typename Scale, typename F>
void forEachInDisc(const Scale& scale, int cx, int cy, int radius, F&& f) {
  const int y0 = std::max(0, cy - radius), y1 = std::min(scale.angle.rows - 1, cy + radius);
  const int x0 = std::max(0, cx - radius), x1 = std::min(scale.angle.cols - 1, cx + radius);
  const float r2max = static_cast<float>(radius * radius);
  for (int y = y0; y <= y1; ++y) {
    const float* ang = scale.angle.template ptr<float>(y);
    const float* mag = scale.magnitude.template ptr<float>(y);
    const float ddy = static_cast<float>(y - cy);
    for (int x = x0; x <= x1; ++x) {
      const float ddx = static_cast<float>(x - cx);
      const float r2 = ddx * ddx + ddy * ddy;
      if (r2 <= r2max) f(r2, ang[x], mag[x]);
    }
  }
}

/// Is v (at row[x]) larger than its 8 neighbours in a response image of row stride `step`?
inline bool aboveItsNeighbours(const float* row, int step, int x, float v) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if ((dx != 0 || dy != 0) && row[dy * step + x + dx] >= v) return false;
  return true;
}

/// Smooths the orientation histogram circularly ([1 2 1]/4, twice) and returns its peak
/// orientation [rad] with parabolic interpolation (§4.4.7.1 c).
float peakOrientation(std::array<float, kMaxOrientationBins + 1>* h, int nb, float to_bin) {
  auto& hist = *h;
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
  return static_cast<float>(
      std::fmod((static_cast<float>(peak) + frac + static_cast<float>(nb)) / to_bin, kTwoPi));
}

/// L2-normalises (contrast invariance, §4.4.7.2), clips at `clip`, renormalises and quantises
/// to bytes.
void quantise(std::array<float, kSwifDescriptorBytes>* d, float clip, uint8_t* descriptor) {
  auto& desc = *d;
  auto normalise = [&desc]() {
    float n2 = 0.0f;
    for (float v : desc) n2 += v * v;
    const float inv = n2 > 0.0f ? 1.0f / std::sqrt(n2) : 0.0f;
    for (float& v : desc) v *= inv;
  };
  normalise();
  for (float& v : desc) v = std::min(v, clip);
  normalise();
  for (int i = 0; i < kSwifDescriptorBytes; ++i)
    descriptor[i] =
        cv::saturate_cast<uint8_t>(desc[static_cast<std::size_t>(i)] * kDescriptorByteScale);
}

}  // namespace

void Swif::computeResponse(const WaveletLevel& w, SwifResponse type, double tensor_sigma,
                           cv::Mat* response, std::vector<cv::Mat>* work) {
  const cv::Size size = w.horizontal.size();
  response->create(size, CV_32F);
  if (type == SwifResponse::kDirections) {
    // §4.4.4 items 1 and 4 read literally: detail in all three directions at the point.
    for (int y = 0; y < size.height; ++y) {
      const float* h = w.horizontal.ptr<float>(y);
      const float* v = w.vertical.ptr<float>(y);
      const float* d = w.diagonal.ptr<float>(y);
      float* r = response->ptr<float>(y);
      for (int x = 0; x < size.width; ++x) r[x] = std::cbrt(std::fabs(h[x] * v[x] * d[x]));
    }
    return;
  }
  // Tensor: (V, H) is the wavelet "gradient" (x and y detail); its second-moment matrix summed
  // over a Gaussian window has a large smaller eigenvalue only where the detail varies in every
  // direction (a corner, not an edge), and unlike the separable H·V·D product it does not change
  // when the image turns (Harris–DWT, [75] in §4.4.5, on the wavelet pyramid).
  work->resize(3);
  cv::Mat& xx = (*work)[0];
  cv::Mat& xy = (*work)[1];
  cv::Mat& yy = (*work)[2];
  cv::multiply(w.vertical, w.vertical, xx);
  cv::multiply(w.vertical, w.horizontal, xy);
  cv::multiply(w.horizontal, w.horizontal, yy);
  for (cv::Mat* m : {&xx, &xy, &yy})
    cv::GaussianBlur(*m, *m, cv::Size(), tensor_sigma, tensor_sigma, cv::BORDER_REFLECT_101);
  for (int y = 0; y < size.height; ++y) {
    const float* a = xx.ptr<float>(y);
    const float* b = xy.ptr<float>(y);
    const float* c = yy.ptr<float>(y);
    float* r = response->ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const float half_diff = 0.5f * (a[x] - c[x]);
      const float lambda_min =
          0.5f * (a[x] + c[x]) - std::sqrt(half_diff * half_diff + b[x] * b[x]);
      r[x] = std::sqrt(std::max(lambda_min, 0.0f));  // in coefficient units, as Th
    }
  }
}

Status SwifOptions::load(const ConfigNode& node) {
  node.get("levels", levels);
  std::vector<int> order_list(orders.begin(), orders.end());
  node.get("orders", order_list);
  orders.clear();
  for (int k : order_list) orders.push_back(k);
  node.get("threshold", threshold);
  node.get("max_features", max_features);
  node.get("grid_cols", grid_cols);
  node.get("grid_rows", grid_rows);
  node.get("window", window);
  node.get("orientation_bins", orientation_bins);
  node.get("orientation_sigma", orientation_sigma);
  node.get("descriptor_clip", descriptor_clip);
  node.getEnum("response", response,
               {{"tensor", SwifResponse::kTensor}, {"directions", SwifResponse::kDirections}});
  node.get("tensor_sigma", tensor_sigma);
  node.getEnum(
      "descriptor", descriptor,
      {{"grid", SwifDescriptorLayout::kGrid}, {"histogram", SwifDescriptorLayout::kHistogram}});
  node.getEnum("scale_axis", scale_axis,
               {{"levels", SwifScaleAxis::kLevels}, {"orders", SwifScaleAxis::kOrders}});
  node.get("scales_per_octave", scales_per_octave);
  node.check(scales_per_octave >= 1 && scales_per_octave <= kMaxScalesPerOctave,
             "scales_per_octave", "must be in 1…4");
  node.check(tensor_sigma > 0, "tensor_sigma", "must be > 0");
  node.check(levels >= 1 && levels <= kMaxLevels, "levels", "must be in 1…8");
  const std::size_t min_orders = scale_axis == SwifScaleAxis::kOrders ? 3 : 1;
  bool orders_ok = orders.size() >= min_orders && !orders.overfull();
  for (std::size_t i = 0; i < orders.size(); ++i) {
    orders_ok = orders_ok && orders[i] >= 1 && orders[i] <= kMaxDaubechiesOrder;
    if (i > 0) orders_ok = orders_ok && orders[i] > orders[i - 1];
  }
  node.check(orders_ok, "orders",
             "must list increasing Daubechies orders in 1…10, at least 3 with scale_axis "
             "orders (extrema need an order above and below)");
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
  // Options built in code skip load(): the checks that keep memory access in bounds again.
  bool orders_ok = !o_.orders.empty() && !o_.orders.overfull();
  for (int k : o_.orders) orders_ok = orders_ok && k >= 1 && k <= kMaxDaubechiesOrder;
  if (!orders_ok || o_.levels < 1 || o_.levels > kMaxLevels || o_.window < 4 ||
      o_.scales_per_octave < 1 || o_.scales_per_octave > kMaxScalesPerOctave ||
      o_.orientation_bins < 4 || o_.orientation_bins > kMaxOrientationBins ||
      (o_.scale_axis == SwifScaleAxis::kOrders && o_.orders.size() < 3))
    return Status::Error("SWIF: invalid options (see SwifOptions::load for the valid ranges)");
  const int n_orders = static_cast<int>(o_.orders.size());
  const int per_octave = o_.scales_per_octave;
  layers_.resize(static_cast<std::size_t>(o_.levels * per_octave));
  for (Layer& layer : layers_) layer.built = false;
  approximation_.resize(static_cast<std::size_t>(o_.levels));
  for (int sub = 0; sub < per_octave; ++sub) {
    // Sub-octave `sub` starts from the input resized by r = 2^(−sub/S): its levels fall between
    // those of sub-octave 0 ("three wavelet levels in each octave", §4.4.7.3 iii).
    const double r = std::exp2(-static_cast<double>(sub) / per_octave);
    if (sub == 0) {
      gray.convertTo(approximation_[0], CV_32F);
    } else {
      cv::resize(gray, base_, cv::Size(), r, r, cv::INTER_AREA);
      base_.convertTo(approximation_[0], CV_32F);
    }
    double offset = 0.0;  // base position of sample 0 of A_l
    for (int l = 0; l < o_.levels; ++l) {
      const cv::Mat& a = approximation_[static_cast<std::size_t>(l)];
      // Levels whose approximation is smaller than the description window are not built.
      if (std::min(a.rows, a.cols) < o_.window) break;
      Layer& layer = layers_[static_cast<std::size_t>(l * per_octave + sub)];
      layer.built = true;
      // Base pixel x ↔ input pixel (x + 0.5)/r − 0.5 (cv::resize's pixel-centre convention).
      layer.factor = static_cast<double>(1 << l) / r;
      layer.offset = offset / r + 0.5 / r - 0.5;
      layer.scales.resize(static_cast<std::size_t>(n_orders));
      for (int s = 0; s < n_orders; ++s) {
        Scale& sc = layer.scales[static_cast<std::size_t>(s)];
        // The next approximation from the first (shortest) wavelet: eq. 4.27 repeated on A.
        const bool next = s == 0 && l + 1 < o_.levels;
        waveletLevel(a, o_.orders[static_cast<std::size_t>(s)], next, &sc.wavelet);
        computeResponse(sc.wavelet, o_.response, o_.tensor_sigma, &sc.response, &work_);
        // Level l's details carry the DC gain 2^l of the orthonormal approximation A_l;
        // dividing it out puts Th and the ranking of all levels in grey levels of the input.
        sc.response *= 1.0 / static_cast<double>(1 << l);
        // Gradient angle from the x axis: V is the detail across x, H across y. (The thesis's
        // arctan(V_k/H_k) measures from the y axis, which turns the wrong way with the image.)
        cv::phase(sc.wavelet.vertical, sc.wavelet.horizontal, sc.angle);
        cv::magnitude(sc.wavelet.horizontal, sc.wavelet.vertical, sc.magnitude);
      }
      // "Multi wavelet" response of the level (eq. 4.27 repeated for each k): the mean over k.
      layer.response.create(a.size(), CV_32F);
      layer.response.setTo(0.0);
      for (const Scale& sc : layer.scales) layer.response += sc.response;
      layer.response *= 1.0 / n_orders;
      if (l + 1 < o_.levels) {
        approximation_[static_cast<std::size_t>(l + 1)] = layer.scales.front().wavelet.next;
        // Sample i of A_{l+1} is sample 2i + delay of A_l (daubechies.h).
        offset += static_cast<double>(1 << l) * approximationDelay(o_.orders.front());
      }
    }
  }
  // Layers by increasing scale, up to the first one not built (a small image's top).
  int n_layers = 0;
  while (n_layers < static_cast<int>(layers_.size()) &&
         layers_[static_cast<std::size_t>(n_layers)].built)
    ++n_layers;
  layers_.resize(static_cast<std::size_t>(n_layers));
  all_.clear();
  for (int j = 0; j < n_layers; ++j) {
    if (o_.scale_axis == SwifScaleAxis::kOrders)
      findMaximaOverOrders(j, &all_);
    else
      findMaximaOverLevels(j, &all_);
  }
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

void Swif::findMaximaOverOrders(int level, std::vector<cv::KeyPoint>* out) const {
  const auto& scales = layers_[static_cast<std::size_t>(level)].scales;
  const float th = static_cast<float>(o_.threshold);
  const auto f = static_cast<float>(layers_[static_cast<std::size_t>(level)].factor);
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
        bool is_max = aboveItsNeighbours(row, step, x, v);
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
        const float ox = parabolaOffset(row[x - 1], v, row[x + 1]);
        const float oy = parabolaOffset(row[x - step], v, row[x + step]);
        cv::KeyPoint kp(toInput(level, static_cast<int>(s), static_cast<float>(x) + ox,
                                static_cast<float>(y) + oy),
                        static_cast<float>(o_.window) * f, -1.0f, v, level, static_cast<int>(s));
        out->push_back(kp);
      }
    }
  }
}

namespace {

// Is v larger than every sample of the 3 × 3 block of `m` around (x, y) (clamped to the image)?
bool aboveBlock(const cv::Mat& m, int x, int y, float v) {
  for (int yy = std::max(0, y - 1); yy <= std::min(m.rows - 1, y + 1); ++yy) {
    const float* row = m.ptr<float>(yy);
    for (int xx = std::max(0, x - 1); xx <= std::min(m.cols - 1, x + 1); ++xx)
      if (row[xx] >= v) return false;
  }
  return true;
}

}  // namespace

void Swif::findMaximaOverLevels(int level, std::vector<cv::KeyPoint>* out) const {
  const Layer& layer = layers_[static_cast<std::size_t>(level)];
  const cv::Mat& r = layer.response;
  const Layer* finer = level > 0 ? &layers_[static_cast<std::size_t>(level - 1)] : nullptr;
  const Layer* coarser = level + 1 < static_cast<int>(layers_.size())
                             ? &layers_[static_cast<std::size_t>(level + 1)]
                             : nullptr;
  const double d = delay(-1);
  // Pixel of `other` at the input position of this layer's pixel (x, y).
  auto at = [&](const Layer& other, int x, int y) {
    const double k = layer.factor / other.factor, c = (layer.offset - other.offset) / other.factor;
    return cv::Point(static_cast<int>(std::lround(k * (x + d) + c - d)),
                     static_cast<int>(std::lround(k * (y + d) + c - d)));
  };
  const float th = static_cast<float>(o_.threshold);
  const auto size = static_cast<float>(o_.window * layer.factor);
  const int step = static_cast<int>(r.step1());
  for (int y = kBorder; y < r.rows - kBorder; ++y) {
    const float* row = r.ptr<float>(y);
    for (int x = kBorder; x < r.cols - kBorder; ++x) {
      const float v = row[x];
      if (v < th) continue;
      const bool is_max = aboveItsNeighbours(row, step, x, v);
      if (!is_max) continue;
      // The 9 + 9 neighbours in the scales below and above (§4.4.3.2 ii), at the same input
      // position.
      if (finer) {
        const cv::Point p = at(*finer, x, y);
        if (!aboveBlock(finer->response, p.x, p.y, v)) continue;
      }
      if (coarser) {
        const cv::Point p = at(*coarser, x, y);
        if (!aboveBlock(coarser->response, p.x, p.y, v)) continue;
      }
      const float ox = parabolaOffset(row[x - 1], v, row[x + 1]);
      const float oy = parabolaOffset(row[x - step], v, row[x + step]);
      out->emplace_back(toInput(level, -1, static_cast<float>(x) + ox, static_cast<float>(y) + oy),
                        size, -1.0f, v, level, 0);
    }
  }
}

double Swif::delay(int order_index) const {
  if (order_index >= 0) return detailDelay(o_.orders[static_cast<std::size_t>(order_index)]);
  double sum = 0.0;  // the level response is the mean over the orders
  for (int k : o_.orders) sum += detailDelay(k);
  return sum / static_cast<double>(o_.orders.size());
}

cv::Point2f Swif::toInput(int level, int order_index, float x, float y) const {
  const Layer& layer = layers_[static_cast<std::size_t>(level)];
  const double f = layer.factor;
  const double d = delay(order_index), off = layer.offset;
  return {static_cast<float>(f * (x + d) + off), static_cast<float>(f * (y + d) + off)};
}

cv::Point2f Swif::toLevel(const cv::KeyPoint& kp) const {
  const Layer& layer = layers_[static_cast<std::size_t>(kp.octave)];
  const double f = layer.factor;
  const int order_index = o_.scale_axis == SwifScaleAxis::kOrders ? kp.class_id : -1;
  const double d = delay(order_index), off = layer.offset;
  return {static_cast<float>((kp.pt.x - off) / f - d), static_cast<float>((kp.pt.y - off) / f - d)};
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
      layers_[static_cast<std::size_t>(kp.octave)].scales[static_cast<std::size_t>(kp.class_id)];
  const cv::Point2f centre = toLevel(kp);
  const int cx = static_cast<int>(std::lround(centre.x));
  const int cy = static_cast<int>(std::lround(centre.y));
  const int radius = o_.window / 2;
  // §4.4.7.1 c: σ = 1.5 × the feature's scale; the scale is taken as half the window radius, so
  // that the orientation window reaches the edge of the description window at 1.33σ.
  const float sigma_o =
      static_cast<float>(o_.orientation_sigma) * 0.5f * static_cast<float>(radius);
  const int nb = o_.orientation_bins;
  std::array<float, kMaxOrientationBins + 1> hist{};
  std::array<float, kSwifDescriptorBytes> desc{};  // unused entries stay 0
  const float to_bin = static_cast<float>(nb / kTwoPi);
  // Pass 1 (§4.4.7.1 b–c): histogram of atan2(V, H) weighted by the norm N and a Gaussian,
  // over a disc (a square window would not rotate with the image).
  forEachInDisc(sc, cx, cy, radius, [&](float r2, float angle, float magnitude) {
    addCircular(hist.data(), nb, angle * to_bin,
                magnitude * std::exp(-r2 / (2 * sigma_o * sigma_o)));
  });
  const float theta = peakOrientation(&hist, nb, to_bin);
  // Pass 2 (§4.4.7.1 d, §4.4.7.2): orientations relative to Θ_f, weighted by the norm N and
  // the descriptor's Gaussian (σ = the window radius, as SIFT's).
  const float sigma_d = static_cast<float>(radius);
  const float inv_2sd2 = 1.0f / (2.0f * sigma_d * sigma_d);
  if (o_.descriptor == SwifDescriptorLayout::kHistogram) {
    // The thesis's descriptor: one histogram of kSwifHistogramBins circular bins.
    const float to_desc = static_cast<float>(kSwifHistogramBins / kTwoPi);
    forEachInDisc(sc, cx, cy, radius, [&](float r2, float angle, float magnitude) {
      float rel = angle - theta;
      if (rel < 0.0f) rel += static_cast<float>(kTwoPi);
      addCircular(desc.data(), kSwifHistogramBins, rel * to_desc,
                  magnitude * std::exp(-r2 * inv_2sd2));
    });
  } else {
    // Grid: the window turned by Θ_f and cut into kSwifCells × kSwifCells cells of
    // kSwifGridBins relative orientations each, samples split bilinearly between cells (as
    // SIFT), so that the descriptor also says where in the window the detail lies.
    const float c = std::cos(theta), s = std::sin(theta);
    const float cell = 2.0f * static_cast<float>(radius) / kSwifCells;
    const float to_grid = static_cast<float>(kSwifGridBins / kTwoPi);
    // The turned square reaches √2 r from the centre.
    const int reach =
        static_cast<int>(std::ceil(static_cast<float>(radius) * static_cast<float>(M_SQRT2)));
    const int gy0 = std::max(0, cy - reach), gy1 = std::min(sc.angle.rows - 1, cy + reach);
    const int gx0 = std::max(0, cx - reach), gx1 = std::min(sc.angle.cols - 1, cx + reach);
    for (int y = gy0; y <= gy1; ++y) {
      const float* ang = sc.angle.ptr<float>(y);
      const float* mag = sc.magnitude.ptr<float>(y);
      const float ddy = static_cast<float>(y - cy);
      for (int x = gx0; x <= gx1; ++x) {
        const float ddx = static_cast<float>(x - cx);
        // Descriptor frame: image offsets turned by −Θ_f.
        const float u = c * ddx + s * ddy, v = -s * ddx + c * ddy;
        const float cu = (u + static_cast<float>(radius)) / cell - 0.5f;
        const float cv = (v + static_cast<float>(radius)) / cell - 0.5f;
        if (cu <= -1.0f || cu >= kSwifCells || cv <= -1.0f || cv >= kSwifCells) continue;
        float rel = ang[x] - theta;
        if (rel < 0.0f) rel += static_cast<float>(kTwoPi);
        const float w = mag[x] * std::exp(-(u * u + v * v) * inv_2sd2);
        const int iu = static_cast<int>(std::floor(cu)), iv = static_cast<int>(std::floor(cv));
        const float au = cu - static_cast<float>(iu), av = cv - static_cast<float>(iv);
        for (int dv = 0; dv <= 1; ++dv) {
          const int row = iv + dv;
          if (row < 0 || row >= kSwifCells) continue;
          const float wv = dv ? av : 1.0f - av;
          for (int du = 0; du <= 1; ++du) {
            const int col = iu + du;
            if (col < 0 || col >= kSwifCells) continue;
            const float wu = du ? au : 1.0f - au;
            addCircular(desc.data() + (row * kSwifCells + col) * kSwifGridBins, kSwifGridBins,
                        rel * to_grid, w * wu * wv);
          }
        }
      }
    }
  }
  quantise(&desc, static_cast<float>(o_.descriptor_clip), descriptor);
  return static_cast<float>(theta * 180.0 / M_PI);
}

Status Swif::detectAndDescribe(const cv::Mat& gray, Features* out) {
  out->type = DescriptorType::kSwif;
  if (Status s = detect(gray, &out->keypoints); !s.ok()) return s;
  describe(&out->keypoints, &out->descriptors);
  return Status::Ok();
}

}  // namespace cvslam::vision
