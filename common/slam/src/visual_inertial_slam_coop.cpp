// VisualInertialSlam's hooks for decentralised cooperation (thesis §6.6, docs/conventions.md): the
// in-state landmarks with their feature index, and the covariance-intersection update
// (ci_updater.h).

#include <algorithm>

#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

std::vector<StateLandmark> VisualInertialSlam::stateLandmarks() const {
  std::vector<StateLandmark> out;
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    StateLandmark l;
    l.id = static_cast<int64_t>(v.key.id);
    l.p_LinN = state_.value(v);
    l.covariance = state_.covarianceOf(v);
    if (const LandmarkBookEntry* r = book_.find(l.id)) {
      l.index = r->index;
      l.descriptor = r->descriptor;
      l.last_seen_us = r->last_seen_us;
    }
    out.push_back(std::move(l));
  }
  std::sort(out.begin(), out.end(),
            [](const StateLandmark& a, const StateLandmark& b) { return a.id < b.id; });
  return out;
}

Status VisualInertialSlam::fuseCovarianceIntersection(const std::vector<int64_t>& ids,
                                                      const Eigen::VectorXd& y,
                                                      const Eigen::MatrixXd& R, double omega1) {
  if (!initialized_) return Status::Error("CI fusion: filter not initialised");
  return ci_updater_.apply(state_, book_, ids, y, R, omega1);
}

Status VisualInertialSlam::fuseIndependent(const std::vector<int64_t>& ids,
                                           const Eigen::VectorXd& y, const Eigen::MatrixXd& R) {
  if (!initialized_) return Status::Error("peer fusion: filter not initialised");
  return ci_updater_.applyIndependent(state_, book_, ids, y, R);
}

bool VisualInertialSlam::isUnmapped(const StereoObservation& obs) const {
  return obs.landmark_id < 0 ||
         (!state_.has(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id))) &&
          !archive_.contains(obs.landmark_id));
}

bool VisualInertialSlam::triangulate(const StereoObservation& obs, Eigen::Vector3d* p_LinN,
                                     Eigen::Matrix3d* covariance) const {
  return initialized_ && initialiser_.triangulate(state_, obs, p_LinN, covariance);
}

Status VisualInertialSlam::mapObservations(const StereoFrameObservations& frame,
                                           std::vector<int64_t>* ids) {
  if (!initialized_) return Status::Error("mapObservations: filter not initialised");
  if (frame.t_us != t_us_) return Status::Error("mapObservations: not the frame just processed");
  int mapped = 0;
  return initialiser_.initialise(state_, book_, archive_, frame, t_us_, &next_fresh_id_, &mapped,
                                 static_cast<int>(frame.observations.size()), ids);
}

}  // namespace cvslam
