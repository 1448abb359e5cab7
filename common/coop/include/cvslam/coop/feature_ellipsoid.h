#pragma once
// Which UAVs cooperate (thesis §6.6.2, docs/conventions.md): each UAV approximates the features it
// observes now by an axis-aligned ellipsoid centred at their mean with semi-axes
// coop_sigma · std (per NED axis); Coop(i, j) = 1 iff the two ellipsoids intersect.
//
// The intersection is tested exactly with the convex one-dimensional test of Gilitschenski &
// Hanebeck ("A robust computational test for overlap of two arbitrary-dimensional
// ellipsoids in fault-detection of Kalman filters", FUSION 2012): with E_i = {x : (x−μ_i)ᵀ
// Σ_i⁻¹ (x−μ_i) ≤ 1},
//   K(s) = 1 − (μ2−μ1)ᵀ [ Σ1/(1−s) + Σ2/s ]⁻¹ (μ2−μ1),   s ∈ (0, 1),
// is convex, and E1 ∩ E2 ≠ ∅ ⇔ min_s K(s) ≥ 0. For diagonal Σ_i the bracket is diagonal, so
// K is a sum of scalar terms and its minimum is found by golden-section search.

#include <Eigen/Core>
#include <vector>

namespace cvslam::coop {

struct FeatureEllipsoid {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d std = Eigen::Vector3d::Zero();  ///< per NED axis [m], unscaled
  int count = 0;                                  ///< features it summarises
  bool valid() const { return count > 0; }
};

/// Mean and (population) standard deviation per axis of the points; count = points.size().
FeatureEllipsoid ellipsoidOf(const std::vector<Eigen::Vector3d>& points);

/// min over s ∈ (0,1) of K(s) for the ellipsoids with centres μ and semi-axes a (> 0).
double minOverlapMeasure(const Eigen::Vector3d& mu1, const Eigen::Vector3d& a1,
                         const Eigen::Vector3d& mu2, const Eigen::Vector3d& a2);

/// Exact intersection test of the ellipsoids mean ± sigma·std. Semi-axes are floored at
/// min_semi_axis_m (> 0) so that a planar or single-feature set still has a volume.
bool ellipsoidsIntersect(const FeatureEllipsoid& e1, const FeatureEllipsoid& e2, double sigma,
                         double min_semi_axis_m);

}  // namespace cvslam::coop
