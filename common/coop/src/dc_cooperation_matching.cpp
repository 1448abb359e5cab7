// DcCooperation's landmark matching (dc_cooperation.h): the descriptor check and the χ² gate of
// two estimates of one landmark, the unmapped observed point a peer's landmark matches
// (map_shared_landmarks), and the archived landmarks where a peer looks (offer_archived).

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "cvslam/vision/descriptor_distance.h"

namespace cvslam::coop {

bool DcCooperation::descriptorsAgree(const std::vector<uint8_t>& a,
                                     const std::vector<uint8_t>& b) const {
  if (a.empty() || a.size() != b.size()) return true;
  const double dist = std::sqrt(static_cast<double>(
      vision::distanceL2Squared(a.data(), b.data(), static_cast<int>(a.size()))));
  return dist <= o_.max_descriptor_distance;
}

double DcCooperation::pairNis(const Eigen::Vector3d& d, const Eigen::Matrix3d& P_a,
                              const Eigen::Matrix3d& P_b, bool independent) {
  return independent ? d.dot((P_a + P_b).ldlt().solve(d)) : ciBoundedNis(d, P_a, P_b);
}

int DcCooperation::matchUnmapped(const SharedLandmark& s, const VisualInertialSlam& slam,
                                 const StereoFrameObservations& frame, bool independent,
                                 double gate, const std::vector<bool>& taken) const {
  double best = std::numeric_limits<double>::infinity();
  int best_k = -1;
  for (std::size_t k = 0; k < frame.observations.size(); ++k) {
    const StereoObservation& obs = frame.observations[k];
    // The index first, as for in-state landmarks: matching by descriptor alone over every
    // observed point let word collisions through the gate where the vehicles are metres off
    // (thesis_loop images: 2 of 7 fused pairs wrong, docs/cooperation.md).
    if (taken[k] || obs.index != s.index || !slam.isUnmapped(obs) ||
        !descriptorsAgree(obs.descriptor, s.descriptor))
      continue;
    // Where mapping it now would put it, with the covariance it would have (the vehicle's
    // uncertainty included): the same gate as for an in-state landmark.
    Eigen::Vector3d p;
    Eigen::Matrix3d P;
    if (!slam.triangulate(obs, &p, &P)) continue;
    const double d2 = pairNis(s.p_LinN - p, P, s.covariance, independent);
    if (d2 <= gate && d2 < best) best = d2, best_k = static_cast<int>(k);
  }
  return best_k;
}

void DcCooperation::archivedInView(const VisualInertialSlam& slam, const FeatureEllipsoid& view,
                                   std::vector<int64_t>* offer) const {
  // The archived landmarks inside the peer's ellipsoid (mean ± coop_sigma·std, floored), the
  // nearest to its centre first, at most max_offered_landmarks.
  if (!view.valid()) return;
  const Eigen::Vector3d a =
      (o_.coop_sigma * view.std).cwiseMax(Eigen::Vector3d::Constant(o_.min_semi_axis_m));
  std::vector<std::pair<double, int64_t>> inside;
  for (const auto& [id, l] : slam.archive().all()) {
    const double q = ((l.p_LinN - view.mean).array() / a.array()).square().sum();
    if (q <= 1.0) inside.emplace_back(q, id);
  }
  const auto n = std::min(inside.size(), static_cast<std::size_t>(o_.max_offered_landmarks));
  std::partial_sort(inside.begin(), inside.begin() + static_cast<std::ptrdiff_t>(n), inside.end());
  for (std::size_t k = 0; k < n; ++k) offer->push_back(inside[k].second);
}

}  // namespace cvslam::coop
