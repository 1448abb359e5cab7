// DcCooperation's landmark matching (dc_cooperation.h): step 5's confirmation of a peer's
// landmarks, the descriptor check and the χ² gate of
// two estimates of one landmark, the unmapped observed point a peer's landmark matches
// (map_shared_landmarks), and the archived landmarks where a peer looks (offer_archived).

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/filter/chi_square.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "cvslam/vision/descriptor_distance.h"
#include "dc_cooperation_detail.h"

namespace cvslam::coop {

std::vector<DcCooperation::ConfirmedPair> DcCooperation::confirm(
    const SharedLandmarks& m, VisualInertialSlam& slam, const StereoFrameObservations& frame,
    bool independent, std::vector<StateLandmark>* local_in, CoopEvent* e) {
  const std::vector<StateLandmark>& local = *local_in;
  const double gate = chiSquareQuantile(o_.gate_probability, detail::kLandmarkDof);
  std::vector<bool> used(local.size(), false);
  std::vector<ConfirmedPair> pairs;
  // Shared landmarks matched to an unmapped observation (mapped below), and those observations.
  StereoFrameObservations to_map;
  to_map.t_us = frame.t_us;
  std::vector<const SharedLandmark*> mapped_for;
  std::vector<bool> taken(frame.observations.size(), false);
  const bool may_map = o_.map_shared_landmarks && slam.time() == frame.t_us;
  for (const SharedLandmark& s : m.landmarks) {
    bool any_index = false, any_descriptor = false;
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_i = local.size();
    for (std::size_t i = 0; i < local.size(); ++i) {
      if (used[i] || local[i].index != s.index) continue;
      any_index = true;
      if (!descriptorsAgree(local[i].descriptor, s.descriptor)) continue;
      any_descriptor = true;
      const double d2 =
          pairNis(s.p_LinN - local[i].p_LinN, local[i].covariance, s.covariance, independent);
      if (d2 <= gate && d2 < best) best = d2, best_i = i;
    }
    if (!any_index && may_map) {
      if (const int k = matchUnmapped(s, slam, frame, independent, gate, taken); k >= 0) {
        taken[static_cast<std::size_t>(k)] = true;
        to_map.observations.push_back(frame.observations[static_cast<std::size_t>(k)]);
        mapped_for.push_back(&s);
        continue;
      }
    }
    if (!any_index) {
      ++stats_.shared_not_in_state;
      ++e->not_in_state;
    } else if (!any_descriptor) {
      ++stats_.rejected_descriptor;
      ++e->rejected_descriptor;
    } else if (best_i == local.size()) {
      ++stats_.rejected_gate;
      ++e->rejected_gate;
    } else {
      used[best_i] = true;
      pairs.push_back({best_i, &s});
    }
  }
  if (to_map.observations.empty()) return pairs;
  // Map the matched points (as step 5 of the filter would, with their own stereo observation),
  // then pair them with the peer's estimates like in-state landmarks.
  std::vector<int64_t> ids;
  if (!slam.mapObservations(to_map, &ids).ok()) return pairs;
  std::vector<int64_t> paired_ids;
  for (const ConfirmedPair& pr : pairs) paired_ids.push_back(local[pr.local].id);
  *local_in = slam.stateLandmarks();  // sorted by id
  const auto position = [&](int64_t id) {
    auto it =
        std::lower_bound(local_in->begin(), local_in->end(), id,
                         [](const StateLandmark& l, int64_t wanted) { return l.id < wanted; });
    return it != local_in->end() && it->id == id ? static_cast<std::size_t>(it - local_in->begin())
                                                 : local_in->size();
  };
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k].local = position(paired_ids[k]);
  for (std::size_t k = 0; k < to_map.observations.size(); ++k) {
    const std::size_t i = ids[k] >= 0 ? position(ids[k]) : local_in->size();
    if (i == local_in->size()) continue;  // not mapped (cannot be triangulated)
    pairs.push_back({i, mapped_for[k]});
    mapped_points_.push_back({frame.t_us, ids[k], to_map.observations[k].z});
    ++e->mapped;
    ++stats_.landmarks_mapped;
  }
  return pairs;
}

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
