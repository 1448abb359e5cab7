#pragma once
// Daubechies orthonormal wavelets db1…db10 and one level of the 2D discrete wavelet transform
// (thesis §4.4.3.1–4.4.3.2, eq. 4.27: [A_k H_k V_k D_k] = DWT(I, "db_k")), used by SWIF (swif.h).
//
// The filter bank is the orthonormal one of MATLAB's dwt2 (the thesis's tool): low-pass h of
// 2N taps (Σh = √2), high-pass g[n] = (−1)^n h[2N−1−n]. Coefficients are those of Daubechies'
// minimum-phase spectral factorisation (Daubechies 1992, Table 6.1), tabulated to 17 digits.

#include <opencv2/core.hpp>
#include <vector>

namespace cvslam::vision {

/// Largest tabulated Daubechies order N (db_N has 2N taps).
constexpr int kMaxDaubechiesOrder = 10;

/// Low-pass analysis filter of db_N, N in 1…kMaxDaubechiesOrder (empty otherwise).
const std::vector<double>& daubechiesLowPass(int order);

/// The detail and approximation images of one DWT level of `approximation` (CV_32F).
struct WaveletLevel {
  cv::Mat horizontal;  ///< H: low-pass along x, high-pass along y (horizontal edges)
  cv::Mat vertical;    ///< V: high-pass along x, low-pass along y (vertical edges)
  cv::Mat diagonal;    ///< D: high-pass along both
  cv::Mat next;        ///< A of the next level: low-pass along both, decimated by 2 (may be
                       ///< left empty, want_next = false)
};

/// Where the filters of db_`order` put their output, relative to the pixel they are written to
/// [pixels of that level]: the energy centroid minus the (integer) anchor. A decimated sample i
/// of the next approximation sits at 2i + approximationDelay; a detail pixel at x + detailDelay
/// (the mean of the low- and high-pass delays: the response mixes H and V).
double approximationDelay(int order);
double detailDelay(int order);

/// One DWT level with db_`order` of `approximation` (CV_32F). The detail images keep the
/// resolution of `approximation` (not decimated, see docs/front_end.md "SWIF": SWIF's departure
/// for a shift-robust, 2× finer localisation); the approximation is decimated as in the DWT.
/// Filters are centred on their energy centroid so that the orders' details align in space.
/// Reuses the buffers of `out` (no allocation when sizes repeat).
void waveletLevel(const cv::Mat& approximation, int order, bool want_next, WaveletLevel* out);

}  // namespace cvslam::vision
