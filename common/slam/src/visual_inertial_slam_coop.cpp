// VisualInertialSlam's hooks for decentralised cooperation (thesis §6.6, docs/conventions.md): the
// in-state landmarks with their feature index, and the covariance-intersection update.

#include <algorithm>
#include <cmath>
#include <string>

#include "cvslam/filter/covariance_helper.h"
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
    if (auto it = info_.find(l.id); it != info_.end()) {
      l.index = it->second.index;
      l.descriptor = it->second.descriptor;
      l.last_seen_us = it->second.last_seen_us;
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
  const auto m = static_cast<Eigen::Index>(ids.size());
  if (m == 0) return Status::Ok();
  if (y.size() != 3 * m || R.rows() != 3 * m || R.cols() != 3 * m)
    return Status::Error("CI fusion: y and R must have 3 rows per landmark");
  if (!std::isfinite(omega1) || omega1 <= 0.0 || omega1 > 1.0)
    return Status::Error("CI fusion: omega1 must be in (0, 1]");
  if (!y.allFinite() || !R.allFinite()) return Status::Error("CI fusion: non-finite peer estimate");
  std::vector<const StateVariable*> vars;
  for (int64_t id : ids) {
    const StateVariable* v = state_.find(VariableKey::landmark(static_cast<uint64_t>(id)));
    if (v == nullptr)
      return Status::Error("CI fusion: landmark " + std::to_string(id) + " is not in the state");
    vars.push_back(v);
  }
  // ω1 = 1 gives all the weight to the local estimate: nothing changes (eq. 6.2).
  if (omega1 >= 1.0) return Status::Ok();
  const double omega2 = 1.0 - omega1;
  // P⁻¹ ← ω1 P⁻¹ + ω2 Hᵀ R⁻¹ H  ⇔  scale the prior by 1/ω1, then an EKF update with R/ω2
  // (docs/cooperation.md). H selects the landmarks, the residual is y − p_L. Ungated: the caller has
  // confirmed every landmark with its own gate on the two estimates.
  Eigen::VectorXd r(3 * m);
  for (Eigen::Index i = 0; i < m; ++i)
    r.segment<3>(3 * i) = y.segment<3>(3 * i) - state_.value(*vars[static_cast<size_t>(i)]);
  if (Status s = CovarianceHelper::scaleCovariance(state_, 1.0 / omega1); !s.ok()) return s;
  MeasurementBatch batch;
  batch.reset(state_.size(), static_cast<int>(3 * m));
  const int g = batch.addObservation(r, R / omega2);
  for (Eigen::Index i = 0; i < m; ++i) {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 * m, 3);
    J.block<3, 3>(3 * i, 0).setIdentity();
    batch.setJacobian(g, *vars[static_cast<size_t>(i)], J);
  }
  UpdateReport report;
  if (Status s = CovarianceHelper::update(state_, batch, UpdatePolicy::ekf(), &report); !s.ok())
    return s;
  // The peer's landmarks can move the vehicle and, through it, the whole local map by far more
  // than the stereo updates do (metres when a drifted UAV meets an accurate one). First-
  // estimates Jacobians linearised at the old landmark positions would then pair the new
  // vehicle with the old map; restart them at the fused means, as loop closing does.
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    if (auto it = info_.find(static_cast<int64_t>(v.key.id)); it != info_.end())
      it->second.first_estimate = state_.value(v);
  }
  return Status::Ok();
}

}  // namespace cvslam
