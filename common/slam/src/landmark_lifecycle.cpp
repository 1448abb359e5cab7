#include "cvslam/slam/landmark_lifecycle.h"

#include <utility>
#include <vector>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

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

void archiveLandmark(SlamState& state, LandmarkArchive& archive, int64_t id,
                     std::optional<LandmarkBookEntry> record, int64_t t_us) {
  const VariableKey key = VariableKey::landmark(static_cast<uint64_t>(id));
  const StateVariable* v = state.find(key);
  if (v == nullptr) return;
  ArchivedLandmark a;
  a.p_LinN = state.value(*v);
  a.covariance = state.covarianceOf(*v);
  if (record) {
    a.index = record->index;
    a.first_seen_us = record->first_seen_us;
    a.last_seen_us = record->last_seen_us;
    a.descriptor = std::move(record->descriptor);
    a.yaw_direction = record->yaw_direction;
  }
  a.archived_us = t_us;
  archive.store(id, std::move(a));
  CovarianceHelper::marginalize(state, key);
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
  CovarianceHelper::addVariable(state, VariableKey::landmark(static_cast<uint64_t>(id)), a->p_LinN,
                                a->covariance + extra_covariance);
  book.add(id, {a->index, a->first_seen_us, a->last_seen_us, std::move(a->descriptor), a->p_LinN,
                a->yaw_direction, false});
  return true;
}

}  // namespace cvslam
