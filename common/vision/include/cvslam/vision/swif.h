#pragma once
// SWIF, the Scale Wavelet Invariant Feature detector and descriptor (thesis §4.4;
// docs/front_end.md "SWIF").
//
// Detector (§4.4.2–4.4.4): a wavelet pyramid of `levels` octaves; at each level the current
// approximation A_l is decomposed with the Daubechies wavelets db_k of `orders` (eq. 4.27) and
// a feature is a maximum of the detail response over its 8 neighbours and the 9 + 9 neighbours
// of the scales above and below (the SIFT-like test of §4.4.3.2 ii) whose response exceeds Th
// (§4.4.6). The response must vanish unless the point has detail in every direction
// (§4.4.4 items 1 and 4: no edge responses).
//
// Descriptor (§4.4.7): orientation Θ_f = the peak of the histogram of the detail orientation
// weighted by the norm √(H_k² + V_k²) and a Gaussian (σ = 1.5 × the feature's scale) over the
// feature's window (§4.4.7.1 a–c); the descriptor holds the orientations relative to Θ_f
// (§4.4.7.1 d) weighted by the norms and a Gaussian centred on the feature, L2-normalised
// (§4.4.7.2), stored as bytes like SIFT's so that the matcher's L2 / L∞ / angle criteria
// (descriptor_matcher.h) apply unchanged.
//
// Each step has the thesis's literal reading as an option (response: directions, scale_axis:
// orders, descriptor: histogram, orders [2, 4, 6, 8]); the defaults are the readings that work
// on our images, measured in docs/results/swif.md and explained in docs/front_end.md "SWIF".

#include <algorithm>
#include <array>
#include <initializer_list>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/vision/daubechies.h"
#include "cvslam/vision/features.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

/// The detail response whose maxima are features (docs/front_end.md "SWIF").
enum class SwifResponse {
  kTensor,      ///< √λ_min of the Gaussian-summed second-moment matrix of (V, H): turns with the
                ///< image (default)
  kDirections,  ///< (|H| |V| |D|)^(1/3): the thesis's "in all three directions" read literally
};

/// A short list of Daubechies orders held inline (at most kMaxDaubechiesOrder, since they are
/// increasing in 1…10): options structs stay free of heap members, which GCC 12 reports as
/// maybe-uninitialised inside aggregate-initialised configs (coop/agent_config.cpp).
class SwifOrders {
 public:
  SwifOrders() = default;
  SwifOrders(std::initializer_list<int> orders) {
    for (int k : orders) push_back(k);
  }
  /// Appends k; beyond kMaxDaubechiesOrder entries k is dropped and the list marked overfull
  /// (invalid: load() and Swif::detect() refuse it).
  void push_back(int k) {
    if (n_ < kMaxDaubechiesOrder)
      k_[static_cast<std::size_t>(n_++)] = k;
    else
      overfull_ = true;
  }
  void clear() { n_ = 0, overfull_ = false; }
  std::size_t size() const { return static_cast<std::size_t>(n_); }
  bool empty() const { return n_ == 0; }
  bool overfull() const { return overfull_; }
  int operator[](std::size_t i) const { return k_[i]; }
  int front() const { return k_[0]; }
  const int* begin() const { return k_.data(); }
  const int* end() const { return k_.data() + n_; }
  bool operator==(const SwifOrders& o) const {
    return n_ == o.n_ && overfull_ == o.overfull_ && std::equal(begin(), end(), o.begin());
  }

 private:
  std::array<int, kMaxDaubechiesOrder> k_{};
  int n_ = 0;
  bool overfull_ = false;
};

/// Where the "scale above and below" of the extremum test (§4.4.3.2 ii) is taken.
enum class SwifScaleAxis {
  kLevels,  ///< adjacent wavelet levels, on the mean response over the orders (default)
  kOrders,  ///< adjacent Daubechies orders of the same level (the thesis read literally)
};

/// What the descriptor holds (§4.4.7.2; docs/front_end.md "SWIF").
enum class SwifDescriptorLayout {
  kGrid,       ///< 4 × 4 cells × 4 orientations relative to Θ_f (default)
  kHistogram,  ///< the thesis's 41-bin histogram of orientations relative to Θ_f
};

struct SwifOptions {
  int levels = 3;  ///< wavelet levels (octaves); "three octaves" (§4.4.7.3 iii)
  /// Daubechies orders of each level (eq. 4.27; db2 and db10 in Figure 4.45), increasing, in
  /// 1…10. scale_axis levels: their responses are averaged (default db1, Haar: its details are
  /// first differences, the only ones whose (V, H) turns like a gradient with the image);
  /// scale_axis orders: at least 3, extrema sought at the inner ones.
  SwifOrders orders = {1};
  /// Th on the response, in grey levels of the input (each level's 2^l DWT gain divided out);
  /// the thesis's Th = 15…25 (§4.4.6) is in raw MATLAB dwt2 units of its response.
  double threshold = 3.0;
  int max_features = 600;  ///< best features kept (by response, spread over the grid)
  int grid_cols = 8;       ///< keypoint grid (keypoint_grid.h); 0 × 0 = off
  int grid_rows = 6;
  /// Description window ms × ms in the feature level's detail pixels (§4.4.8, Table 4.2: ms = 8
  /// of decimated DWT pixels; our details are not decimated, daubechies.h, so 16 would be the
  /// same area; 12 matched best on the rendered pairs).
  int window = 12;
  int orientation_bins = 40;  ///< orientation-assignment histogram: 360/bin, bin = 9° (§4.4.8)
  double orientation_sigma = 1.5;  ///< Gaussian σ = this × the feature's scale (§4.4.7.1 c)
  double descriptor_clip = 0.5;    ///< normalised entries clipped here, then renormalised
                                   ///< (one strong edge must not own the descriptor)

  SwifResponse response = SwifResponse::kTensor;      ///< tensor | directions
  SwifScaleAxis scale_axis = SwifScaleAxis::kLevels;  ///< levels | orders
  double tensor_sigma = 1.0;
  /// Pyramids per octave, started from the input resized by 2^(−s/S), s = 0…S−1, so that the
  /// scale test compares scales 2^(1/S) apart instead of an octave; 1 = a single DWT pyramid.
  int scales_per_octave = 1;
  SwifDescriptorLayout descriptor =
      SwifDescriptorLayout::kGrid;  ///< grid | histogram  ///< Gaussian window of the tensor
                                    ///< [detail pixels of the level]

  Status load(const ConfigNode& node);
};

/// The thesis's descriptor: one histogram of 1 + 360°/9° = 41 orientations (Table 4.3).
constexpr int kSwifHistogramBins = 41;
/// The grid descriptor: 4 × 4 cells of 4 relative orientations.
constexpr int kSwifCells = 4;
constexpr int kSwifGridBins = 4;
/// Bytes of a SWIF descriptor, either layout (the histogram leaves the last 23 at 0, which no
/// distance of descriptor_distance.h notices).
constexpr int kSwifDescriptorBytes = kSwifCells * kSwifCells * kSwifGridBins;
static_assert(kSwifDescriptorBytes >= kSwifHistogramBins);

class Swif {
 public:
  explicit Swif(const SwifOptions& options) : o_(options) {}

  /// Builds the wavelet pyramid of `gray` (CV_8UC1) and keeps at most max_features maxima
  /// (pt in input pixels, size = the window in input pixels, octave = layer (scale) index,
  /// class_id = order index, angle −1: no orientation yet).
  Status detect(const cv::Mat& gray, std::vector<cv::KeyPoint>* keypoints);
  /// Orientation (angle, degrees) and descriptors of keypoints of the last detect().
  void describe(std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors);
  /// detect() then describe() into `out`.
  Status detectAndDescribe(const cv::Mat& gray, Features* out);

 private:
  struct Scale {  // one (level, order) of the pyramid
    WaveletLevel wavelet;
    cv::Mat response;   ///< (|H| |V| |D|)^(1/3)
    cv::Mat angle;      ///< atan2(V, H) [rad, 0…2π)
    cv::Mat magnitude;  ///< √(H² + V²)
  };
  static void computeResponse(const WaveletLevel& w, SwifResponse type, double tensor_sigma,
                              cv::Mat* response, std::vector<cv::Mat>* work);
  void findMaximaOverOrders(int level, std::vector<cv::KeyPoint>* out) const;
  void findMaximaOverLevels(int level, std::vector<cv::KeyPoint>* out) const;
  /// Detail-pixel delay of an order (−1: the mean over the orders, the level response's).
  double delay(int order_index) const;
  /// Detail pixel (x, y) of `level` (response of order `order_index`, −1 = level mean) in input
  /// pixels, and back for a keypoint.
  cv::Point2f toInput(int level, int order_index, float x, float y) const;
  cv::Point2f toLevel(const cv::KeyPoint& kp) const;
  float describeOne(const cv::KeyPoint& kp, uint8_t* descriptor) const;

  struct Layer {                // one level of one sub-octave pyramid
    std::vector<Scale> scales;  ///< [order index]
    cv::Mat response;           ///< mean response over the orders
    double factor = 1.0;        ///< input pixels per detail pixel
    double offset = 0.0;        ///< input position of detail sample 0, before the filter delay
    bool built = false;
  };

  SwifOptions o_;
  std::vector<Layer> layers_;           ///< by increasing scale: level l, sub-octave s at l·S + s
  std::vector<cv::Mat> approximation_;  ///< A_0 … A_{levels−1} of the sub-octave being built
  cv::Mat base_;                        ///< the resized input of a sub-octave
  std::vector<cv::KeyPoint> all_;
  std::vector<cv::Mat> work_;  ///< tensor products (reused)
};

}  // namespace cvslam::vision
