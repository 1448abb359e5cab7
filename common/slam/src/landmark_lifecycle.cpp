#include "cvslam/slam/landmark_lifecycle.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

std::vector<int64_t> observedLandmarkIds(const StereoFrameObservations& frame) {
  std::vector<int64_t> ids;
  ids.reserve(frame.observations.size());
  for (const StereoObservation& obs : frame.observations)
    if (obs.landmark_id >= 0) ids.push_back(obs.landmark_id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

Eigen::Vector3d frameVirtualPoint(const KNearestMapManager& manager, const StereoCamera& camera,
                                  const SlamState& state, const VariableKey& vehicle,
                                  const StereoFrameObservations& frame) {
  const vehicle_model::Pose x = vehicle_model::pose(state, *state.find(vehicle));
  const StereoCameraOptions& c = camera.options();
  std::vector<double> depths;
  depths.reserve(frame.observations.size());
  for (const StereoObservation& obs : frame.observations) {
    const double disparity = obs.z(0) - obs.z(2);
    if (disparity > 0.0) depths.push_back(c.fx * c.baseline / disparity);
  }
  return KNearestMapManager::virtualPoint(camera, x.p_BinN, x.R_BtoN, manager.sceneDepth(depths));
}

namespace {

/// Of the held landmarks beyond the recent ones (`*pool`, ids), keeps `capacity` spread over
/// the map as anchors and leaves in *pool those to marginalise: while too many remain, of the
/// two nearest each other the one with the larger position variance goes (ties: the larger
/// id), so the anchors thin evenly where the map is dense and keep the better known ones.
void thinAnchors(const SlamState& state, int capacity, std::vector<int64_t>* pool) {
  struct Anchor {
    int64_t id;
    Eigen::Vector3d p;
    double variance;
  };
  std::vector<Anchor> anchors;
  for (const int64_t id : *pool) {
    const StateVariable* v = state.find(VariableKey::heldLandmark(static_cast<uint64_t>(id)));
    anchors.push_back({id, state.value(*v), state.covarianceOf(*v).trace()});
  }
  std::vector<int64_t> leaving;
  while (anchors.size() > static_cast<std::size_t>(capacity)) {
    std::size_t a = 0, b = 1;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < anchors.size(); ++i) {
      for (std::size_t j = i + 1; j < anchors.size(); ++j) {
        const double d = (anchors[i].p - anchors[j].p).squaredNorm();
        if (d < nearest) {
          nearest = d;
          a = i;
          b = j;
        }
      }
    }
    const Anchor& x = anchors[a];
    const Anchor& y = anchors[b];
    const bool drop_a = x.variance != y.variance ? x.variance > y.variance : x.id > y.id;
    const std::size_t drop = drop_a ? a : b;
    leaving.push_back(anchors[drop].id);
    anchors.erase(anchors.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  *pool = std::move(leaving);
}

}  // namespace

void archiveLandmark(SlamState& state, LandmarkArchive& archive, int64_t id,
                     std::optional<LandmarkBookEntry> record, int64_t t_us, int held_capacity,
                     const std::vector<Eigen::Vector3d>& keep_near, int anchor_capacity) {
  const VariableKey key = VariableKey::landmark(static_cast<uint64_t>(id));
  const StateVariable* v = state.find(key);
  if (v == nullptr) return;
  ArchivedLandmark a;
  a.p_LinN = state.value(*v);
  a.first_estimate = a.p_LinN;  // the record's, when there is one
  a.covariance = state.covarianceOf(*v);
  if (record) {
    a.index = record->index;
    a.first_seen_us = record->first_seen_us;
    a.last_seen_us = record->last_seen_us;
    a.descriptor = std::move(record->descriptor);
    a.yaw_direction = record->yaw_direction;
    a.constrained = record->constrained;
    a.first_estimate = record->first_estimate;
  }
  a.archived_us = t_us;
  archive.store(id, std::move(a));
  if (held_capacity <= 0) {
    CovarianceHelper::marginalize(state, key);
    return;
  }
  CovarianceHelper::rekey(state, key, VariableKey::heldLandmark(static_cast<uint64_t>(id)));
  // Keep the held_capacity nearest to keep_near, or the most recently archived.
  struct Held {
    double distance;  // to the nearest keep_near point (0 without points)
    int64_t archived_us;
    int64_t id;
  };
  std::vector<Held> held;
  for (const StateVariable& var : state.variables()) {
    if (var.key.kind != VariableKey::Kind::kHeldLandmark) continue;
    const auto held_id = static_cast<int64_t>(var.key.id);
    const ArchivedLandmark* entry = archive.find(held_id);
    double distance = keep_near.empty() ? 0.0 : std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : keep_near)
      distance = std::min(distance, (state.value(var) - p).norm());
    held.push_back({distance, entry != nullptr ? entry->archived_us : 0, held_id});
  }
  // Leaving first: the farthest, then the oldest, then the smaller id.
  std::sort(held.begin(), held.end(), [](const Held& l, const Held& r) {
    if (l.distance != r.distance) return l.distance > r.distance;
    if (l.archived_us != r.archived_us) return l.archived_us < r.archived_us;
    return l.id < r.id;
  });
  const std::size_t excess =
      held.size() - std::min(held.size(), static_cast<std::size_t>(held_capacity));
  std::vector<int64_t> leaving_ids;
  for (std::size_t i = 0; i < excess; ++i) leaving_ids.push_back(held[i].id);
  if (anchor_capacity > 0) thinAnchors(state, anchor_capacity, &leaving_ids);
  for (const int64_t leaving : leaving_ids) {
    const VariableKey held_key = VariableKey::heldLandmark(static_cast<uint64_t>(leaving));
    // The archive keeps the marginal as it is now (NH∞ updates may have inflated it).
    if (std::optional<ArchivedLandmark> entry = archive.take(leaving)) {
      entry->covariance = state.covarianceOf(*state.find(held_key));
      archive.store(leaving, std::move(*entry));
    }
    CovarianceHelper::marginalize(state, held_key);
  }
}

bool isHeld(const SlamState& state, int64_t id) {
  return state.has(VariableKey::heldLandmark(static_cast<uint64_t>(id)));
}

bool mayReenter(const SlamState& state, int64_t id, const ArchivedLandmark& a, int64_t t_us,
                const SlamOptions& options) {
  return isHeld(state, id) ||
         static_cast<double>(t_us - a.archived_us) * 1e-6 >= options.reactivation_min_age_s;
}

SlamOptions::Reentry reentryOf(const ArchivedLandmark& a, int64_t t_us,
                               const SlamOptions& options) {
  const bool recent =
      static_cast<double>(t_us - a.last_seen_us) * 1e-6 < options.loop_closure_min_age_s;
  return recent ? options.recent_reentry : options.reactivation;
}

bool reactivateLandmark(SlamState& state, LandmarkBook& book, LandmarkArchive& archive, int64_t id,
                        const Eigen::Matrix3d& extra_covariance) {
  std::optional<ArchivedLandmark> a = archive.take(id);
  if (!a) return false;
  const VariableKey key = VariableKey::landmark(static_cast<uint64_t>(id));
  const bool held = isHeld(state, id);
  if (held) {
    CovarianceHelper::rekey(state, VariableKey::heldLandmark(static_cast<uint64_t>(id)), key);
  } else {
    CovarianceHelper::addVariable(state, key, a->p_LinN, a->covariance + extra_covariance);
  }
  // A held landmark comes back as it left: correlated (OC-EKF applies), linearised at its
  // first estimate (FEJ). Any other re-enters as a new, independent prior at its archived mean.
  book.add(id, {a->index, a->first_seen_us, a->last_seen_us, std::move(a->descriptor),
                held ? a->first_estimate : a->p_LinN, a->yaw_direction, held && a->constrained});
  return true;
}

}  // namespace cvslam
