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

}  // namespace cvslam
