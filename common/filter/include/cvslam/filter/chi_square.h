#pragma once
// χ² distribution for Mahalanobis gating of measurements, on Boost.Math (Debian's
// libboost-math-dev, header-only): the CDF and the quantile to full double precision.

namespace cvslam {

/// P(χ²_dof ≤ x). dof ≥ 1; x ≤ 0 gives 0.
double chiSquareCdf(double x, int dof);

/// x such that P(χ²_dof ≤ x) = probability, for 0 < probability < 1 and dof ≥ 1; NaN otherwise.
double chiSquareQuantile(double probability, int dof);

/// Wilson–Hilferty cube-root approximation of the quantile, for estimates by hand (~1 %
/// accurate for dof ≥ 3 at the probabilities used for gating).
double chiSquareQuantileWilsonHilferty(double probability, int dof);

/// Standard normal quantile Φ⁻¹(p); ∓infinity at p ≤ 0 and p ≥ 1.
double normalQuantile(double probability);

}  // namespace cvslam
