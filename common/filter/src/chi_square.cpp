#include "cvslam/filter/chi_square.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cvslam {
namespace {

/// ln Γ(dof/2) for an integer dof ≥ 1, by the recurrence Γ(a+1) = a Γ(a) from Γ(1) = 1 or
/// Γ(1/2) = √π (avoids std::lgamma, which writes the global signgam on glibc).
double logGammaHalf(int dof) {
  double a = (dof % 2 == 0) ? 1.0 : 0.5;
  double log_gamma = (dof % 2 == 0) ? 0.0 : 0.5 * std::log(M_PI);
  for (; a < 0.5 * dof; a += 1.0) log_gamma += std::log(a);
  return log_gamma;
}

/// Regularised lower incomplete gamma P(a, x) (Numerical Recipes §6.2: series below a + 1,
/// Lentz continued fraction for Q = 1 − P above).
double regularisedGammaP(double a, double x, double log_gamma_a) {
  if (x <= 0.0) return 0.0;
  constexpr double kEps = 1e-16;
  const double log_prefactor = -x + a * std::log(x) - log_gamma_a;
  if (x < a + 1.0) {
    double ap = a, del = 1.0 / a, sum = del;
    for (int n = 0; n < 10000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * kEps) break;
    }
    return sum * std::exp(log_prefactor);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < kEps) break;
  }
  return 1.0 - std::exp(log_prefactor) * h;
}

double chiSquarePdf(double x, int dof, double log_gamma) {
  if (x <= 0.0) return 0.0;
  const double a = 0.5 * dof;
  return std::exp((a - 1.0) * std::log(x) - 0.5 * x - a * std::log(2.0) - log_gamma);
}

}  // namespace

double normalQuantile(double p) {
  if (p <= 0.0) return -std::numeric_limits<double>::infinity();
  if (p >= 1.0) return std::numeric_limits<double>::infinity();
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                 -2.759285104469687e+02, 1.383577518672690e+02,
                                 -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                 -1.556989798598866e+02, 6.680131188771972e+01,
                                 -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                 -2.400758277161838e+00, -2.549732539343734e+00,
                                 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                                 2.445134137142996e+00, 3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  double x = 0.0;
  if (p < kLow || p > 1.0 - kLow) {
    const double q = std::sqrt(-2.0 * std::log(p < kLow ? p : 1.0 - p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    if (p > kLow) x = -x;
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  // One Halley step on Φ(x) − p brings Acklam's 1e-9 to machine precision.
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

double chiSquareCdf(double x, int dof) {
  if (dof < 1 || x <= 0.0) return 0.0;
  return regularisedGammaP(0.5 * dof, 0.5 * x, logGammaHalf(dof));
}

double chiSquareQuantileWilsonHilferty(double probability, int dof) {
  const double k = dof;
  const double s = 2.0 / (9.0 * k);
  const double t = 1.0 - s + normalQuantile(probability) * std::sqrt(s);
  return k * std::max(t * t * t, 1e-6);
}

double chiSquareQuantile(double probability, int dof) {
  if (dof < 1 || !(probability > 0.0) || !(probability < 1.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double log_gamma = logGammaHalf(dof);
  // Bracket [lo, hi] around the root, then safeguarded Newton (bisect when Newton leaves it).
  double x = chiSquareQuantileWilsonHilferty(probability, dof);
  double lo = 0.0, hi = std::max(x, 1.0);
  while (chiSquareCdf(hi, dof) < probability) hi *= 2.0;
  for (int it = 0; it < 200; ++it) {
    const double f = regularisedGammaP(0.5 * dof, 0.5 * x, log_gamma) - probability;
    if (f < 0.0)
      lo = x;
    else
      hi = x;
    const double pdf = chiSquarePdf(x, dof, log_gamma);
    double next = pdf > 0.0 ? x - f / pdf : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-13 * std::max(1.0, x)) return next;
    x = next;
  }
  return x;
}

}  // namespace cvslam
