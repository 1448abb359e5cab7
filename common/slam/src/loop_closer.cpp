#include "cvslam/slam/loop_closer.h"

#include <algorithm>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/loop_alignment.h"
#include "cvslam/slam/observability_constraint.h"

namespace cvslam {

LoopCloser::LoopCloser(const VariableKey& vehicle, const StereoCamera& camera,
                       const SlamOptions& options)
    : vehicle_(vehicle), camera_(camera), o_(options) {}

void LoopCloser::detect(LandmarkBook& book, const StereoFrameObservations& frame, int64_t t_us,
                        LoopReport* report) {
  const auto min_age_us = static_cast<int64_t>(o_.loop_closure_min_age_s * 1e6);
  const auto window_us = static_cast<int64_t>(o_.loop_closure_window_s * 1e6);
  book.expirePendingLoops(t_us, window_us);
  loop_ids_.clear();
  for (const StereoObservation& obs : frame.observations) {
    LandmarkBookEntry* record = book.find(obs.landmark_id);
    if (record == nullptr) continue;
    if (t_us - record->last_seen_us >= min_age_us) {
      book.markPendingLoop(obs.landmark_id, t_us);
      ++report->loop_landmarks;
    }
    record->last_seen_us = t_us;
    if (book.isPendingLoop(obs.landmark_id)) loop_ids_.push_back(obs.landmark_id);
  }
  std::sort(loop_ids_.begin(), loop_ids_.end());
}

Status LoopCloser::process(SlamState& state, LandmarkBook& book,
                           const StereoFrameObservations& frame, int64_t t_us,
                           StereoUpdater& updater, const UpdatePolicy& policy,
                           FilterStatistics* stats, LoopReport* report) {
  detect(book, frame, t_us, report);
  LoopAlignment fit;
  if (o_.loop_closure_min_landmarks == 0 ||
      static_cast<int>(loop_ids_.size()) < o_.loop_closure_min_landmarks ||
      align(state, frame, &fit) < o_.loop_closure_min_landmarks) {
    return Status::Ok();
  }
  // The first linearisation point: the vehicle moved by the alignment. The loop landmarks
  // stay (they are in the old frame); the other landmarks have no rows in this update.
  SlamState start = state;
  const StateVariable* veh = start.find(vehicle_);
  vehicle_model::moveRigidly(start, *veh, fit.apply(vehicle_model::pose(start, *veh).p_BinN),
                             fit.yaw);
  Eigen::VectorXd mean_before = state.mean();
  // Plain Jacobians: Gauss–Newton needs ∂h/∂x at each linearisation point (the first
  // estimates of the loop landmarks' observer are from before the drift).
  const CovarianceHelper::Linearisation linearise = [&](const SlamState& at,
                                                        MeasurementBatch* batch) {
    return updater.linearise(at, book, frame, StereoUpdater::Selection::kOnlyListed, loop_ids_,
                             StereoUpdater::Jacobians::kPlain, 1.0, batch);
  };
  IteratedUpdateOptions iterated;
  iterated.max_iterations = o_.loop_closure_passes;
  iterated.joint_gate_probability = o_.loop_closure_gate_probability;
  UpdatePolicy ungated = policy;  // the joint gate replaces the per-observation one
  ungated.gate_probability = 0.0;
  UpdateReport u;
  const Status s = CovarianceHelper::iteratedUpdate(state, std::move(start), linearise, iterated,
                                                    ungated, &batch_, &u);
  if (!s.ok()) return s;
  stats->add(u);
  report->theta_reduced = u.theta_reduced;
  report->nis = u.nis;
  report->nis_dof = u.rows;
  if (u.rejected_jointly || u.rows == 0) {
    // Refused: the loop landmarks stay pending (out of the gated updates) until the window
    // ends or a later frame's loop passes the gate.
    report->loop_refused = u.rejected_jointly;
    return Status::Ok();
  }
  report->loop_closure = true;
  followCorrection(state, mean_before, vehicle_, &book);
  report->mean_before = std::move(mean_before);
  for (int64_t id : loop_ids_) book.endPendingLoop(id);
  return Status::Ok();
}

int LoopCloser::align(const SlamState& state, const StereoFrameObservations& frame,
                      LoopAlignment* fit_out) {
  const StateVariable* veh = state.find(vehicle_);
  if (veh == nullptr) return 0;
  const vehicle_model::Pose x = vehicle_model::pose(state, *veh);
  std::vector<int64_t> ids;
  std::vector<LoopPair> pairs;
  for (const StereoObservation& obs : frame.observations) {
    if (!std::binary_search(loop_ids_.begin(), loop_ids_.end(), obs.landmark_id)) continue;
    const StateVariable* lm =
        state.find(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id)));
    Eigen::Vector3d p_observed;
    if (lm == nullptr || !camera_.triangulate(obs.z, x, &p_observed).ok()) continue;
    ids.push_back(obs.landmark_id);
    pairs.push_back({p_observed, state.value(*lm)});
  }
  // Fit, drop pairs that disagree with the fit (wrong associations), fit again.
  const Eigen::Vector3d pivot = x.p_BinN;
  Expected<LoopAlignment> fit = alignLoop(pairs, pivot);
  for (int round = 0; round < 2 && fit.ok(); ++round) {
    std::vector<int64_t> kept_ids;
    std::vector<LoopPair> kept;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if ((fit->apply(pairs[i].p_observed_N) - pairs[i].p_map_N).norm() <=
          o_.loop_closure_max_residual_m) {
        kept_ids.push_back(ids[i]);
        kept.push_back(pairs[i]);
      }
    }
    ids.swap(kept_ids);
    pairs.swap(kept);
    fit = alignLoop(pairs, pivot);
  }
  loop_ids_.clear();
  if (!fit.ok() || static_cast<int>(ids.size()) < o_.loop_closure_min_landmarks) return 0;
  loop_ids_ = ids;
  std::sort(loop_ids_.begin(), loop_ids_.end());
  *fit_out = *fit;
  return static_cast<int>(loop_ids_.size());
}

void followCorrection(const SlamState& state, const Eigen::VectorXd& mean_before,
                      const VariableKey& vehicle, LandmarkBook* book) {
  // u = e3 × p is linear in p: a move by Δ adds e3 × Δ.
  const auto moved = [&](const StateVariable& v, int position_entry) -> Eigen::Vector3d {
    return state.value(v).segment<3>(position_entry) -
           mean_before.segment<3>(v.index + position_entry);
  };
  for (const StateVariable& v : state.variables()) {
    if (v.key == vehicle) {
      Eigen::VectorXd u_v = book->vehicleYawDirection();
      if (u_v.size() < 3) continue;
      u_v.head<3>() += yawDirectionOfPoint(moved(v, vehicle::kPosition));
      book->setVehicleYawDirection(u_v);
      continue;
    }
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    LandmarkBookEntry* record = book->find(static_cast<int64_t>(v.key.id));
    if (record == nullptr) continue;
    const Eigen::Vector3d delta = moved(v, 0);
    record->first_estimate += delta;
    record->yaw_direction += yawDirectionOfPoint(delta);
  }
}

}  // namespace cvslam
