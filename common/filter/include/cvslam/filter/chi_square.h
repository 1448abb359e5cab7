#pragma once
// χ² distribution for Mahalanobis gating of measurements (no Boost): the CDF through the
// regularised lower incomplete gamma function P(k/2, x/2) (series and continued fraction),
// and the quantile by Newton/bisection started from the Wilson–Hilferty approximation.
// Exact to ~1e-10 for the integer degrees of freedom used by the filters.

namespace cvslam {

/// P(χ²_dof ≤ x). dof ≥ 1; x ≤ 0 gives 0.
double chiSquareCdf(double x, int dof);

/// x such that P(χ²_dof ≤ x) = probability, for 0 < probability < 1 and dof ≥ 1.
double chiSquareQuantile(double probability, int dof);

/// Wilson–Hilferty cube-root approximation of the quantile (start value; ~1 % accurate for
/// dof ≥ 3 at the probabilities used for gating).
double chiSquareQuantileWilsonHilferty(double probability, int dof);

/// Standard normal quantile Φ⁻¹(p) (Acklam's rational approximation refined by one Halley
/// step; |error| < 1e-12).
double normalQuantile(double probability);

}  // namespace cvslam
