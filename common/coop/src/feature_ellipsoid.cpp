#include "cvslam/coop/feature_ellipsoid.h"

#include <algorithm>
#include <cmath>

#include "cvslam/core/golden_section.h"

namespace cvslam::coop {

namespace {
// Golden-section search on a convex function of s ∈ (0, 1): 1e-12 in s is far below what
// changes the sign of K for ellipsoids of metres.
constexpr double kSearchTolerance = 1e-12;
constexpr int kMaxIterations = 200;
}  // namespace

FeatureEllipsoid ellipsoidOf(const std::vector<Eigen::Vector3d>& points) {
  FeatureEllipsoid e;
  e.count = static_cast<int>(points.size());
  if (points.empty()) return e;
  for (const Eigen::Vector3d& p : points) e.mean += p;
  e.mean /= static_cast<double>(points.size());
  Eigen::Vector3d var = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) var += (p - e.mean).cwiseAbs2();
  e.std = (var / static_cast<double>(points.size())).cwiseSqrt();
  return e;
}

double minOverlapMeasure(const Eigen::Vector3d& mu1, const Eigen::Vector3d& a1,
                         const Eigen::Vector3d& mu2, const Eigen::Vector3d& a2) {
  const Eigen::Vector3d d2 = (mu2 - mu1).cwiseAbs2();
  const Eigen::Vector3d s1 = a1.cwiseAbs2();
  const Eigen::Vector3d s2 = a2.cwiseAbs2();
  // K(s) = 1 − Σ_k d_k² / (Σ1_k/(1−s) + Σ2_k/s) for diagonal Σ_i = diag(a_i²).
  auto K = [&](double s) {
    double q = 0.0;
    for (int k = 0; k < 3; ++k) q += d2(k) / (s1(k) / (1.0 - s) + s2(k) / s);
    return 1.0 - q;
  };
  return minimizeGoldenSection(K, 0.0, 1.0, kSearchTolerance, kMaxIterations).value;
}

bool ellipsoidsIntersect(const FeatureEllipsoid& e1, const FeatureEllipsoid& e2, double sigma,
                         double min_semi_axis_m) {
  if (!e1.valid() || !e2.valid()) return false;
  const Eigen::Vector3d floor = Eigen::Vector3d::Constant(min_semi_axis_m);
  const Eigen::Vector3d a1 = (sigma * e1.std).cwiseMax(floor);
  const Eigen::Vector3d a2 = (sigma * e2.std).cwiseMax(floor);
  return minOverlapMeasure(e1.mean, a1, e2.mean, a2) >= 0.0;
}

}  // namespace cvslam::coop
