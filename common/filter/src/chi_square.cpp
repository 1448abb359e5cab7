#include "cvslam/filter/chi_square.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>

namespace cvslam {

double normalQuantile(double p) {
  if (p <= 0.0) return -std::numeric_limits<double>::infinity();
  if (p >= 1.0) return std::numeric_limits<double>::infinity();
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}

double chiSquareCdf(double x, int dof) {
  if (dof < 1 || x <= 0.0) return 0.0;
  return boost::math::cdf(boost::math::chi_squared_distribution<double>(dof), x);
}

double chiSquareQuantileWilsonHilferty(double probability, int dof) {
  const double k = dof;
  const double s = 2.0 / (9.0 * k);
  const double t = 1.0 - s + normalQuantile(probability) * std::sqrt(s);
  return k * std::max(t * t * t, 1e-6);
}

double chiSquareQuantile(double probability, int dof) {
  // Boost throws outside (0, 1) and for dof < 1; gating callers expect NaN there.
  if (dof < 1 || !(probability > 0.0) || !(probability < 1.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), probability);
}

}  // namespace cvslam
