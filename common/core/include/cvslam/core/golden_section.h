#pragma once
// Golden-section search for the minimum of a unimodal function on [lo, hi]: the 1-D convex
// problems of covariance intersection (ω minimising a trace or determinant, thesis §6.6.4)
// and of the exact ellipsoid intersection test (feature_ellipsoid.h).

namespace cvslam {

struct GoldenSectionResult {
  double x = 0.0;      ///< argmin (interior estimate; boundaries are the caller's business)
  double value = 0.0;  ///< f at the better of the last two probes
};

/// Shrinks [lo, hi] by the golden ratio until it is narrower than `tolerance` or
/// `max_iterations` probes were made. `f` must be unimodal (e.g. convex) on [lo, hi].
template <typename F>
GoldenSectionResult minimizeGoldenSection(const F& f, double lo, double hi, double tolerance,
                                          int max_iterations = 200) {
  constexpr double kGolden = 0.6180339887498949;  // (√5 − 1)/2
  double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < max_iterations && hi - lo > tolerance; ++i) {
    if (f1 < f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - kGolden * (hi - lo);
      f1 = f(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + kGolden * (hi - lo);
      f2 = f(x2);
    }
  }
  return {0.5 * (lo + hi), f1 < f2 ? f1 : f2};
}

}  // namespace cvslam
