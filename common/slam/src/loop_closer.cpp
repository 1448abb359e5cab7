#include "cvslam/slam/loop_closer.h"

#include <algorithm>

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
  if (o_.loop_closure_min_landmarks == 0 ||
      static_cast<int>(loop_ids_.size()) < o_.loop_closure_min_landmarks ||
      align(state, book, frame, t_us) < o_.loop_closure_min_landmarks) {
    return Status::Ok();
  }
  // Loop closing: the aligned loop landmarks first, ungated, iterated.
  UpdatePolicy ungated = policy;
  ungated.gate_probability = 0.0;
  const int loop_passes = o_.loop_closure_passes;
  std::vector<UpdateReport> passes;
  const Status s =
      updater.update(state, book, frame, loop_passes, StereoUpdater::Selection::kOnlyListed,
                     loop_ids_, ungated, &passes);
  for (std::size_t pass = 0; pass < passes.size(); ++pass) {
    if (pass + 1 == static_cast<std::size_t>(loop_passes)) stats->add(passes[pass]);
    report->theta_reduced = report->theta_reduced || passes[pass].theta_reduced;
  }
  if (!s.ok()) return s;
  report->loop_closure = true;
  for (int64_t id : loop_ids_) book.endPendingLoop(id);
  return Status::Ok();
}

int LoopCloser::align(SlamState& state, LandmarkBook& book, const StereoFrameObservations& frame,
                      int64_t t_us) {
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

  // Move the linearisation point: the vehicle and the landmarks that drifted with it (all
  // landmarks of the book but the loop ones) by the fitted rigid motion. The update that
  // follows then sees small innovations and corrects the covariance as usual.
  vehicle_model::moveRigidly(state, *veh, fit->apply(x.p_BinN), fit->yaw);
  // The alignment moves the estimate along the unobservable directions; their tracked
  // directions move with it.
  Eigen::VectorXd u_v = book.vehicleYawDirection();
  u_v.head<3>() = moveYawDirection(u_v.head<3>(), *fit);
  book.setVehicleYawDirection(u_v);
  const auto min_age_us = static_cast<int64_t>(o_.loop_closure_min_age_s * 1e6);
  for (const StateVariable& v : state.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(v.key.id);
    if (std::binary_search(loop_ids_.begin(), loop_ids_.end(), id)) continue;
    // Only landmarks seen recently drifted with the vehicle; old ones (the full map keeps
    // them in the state) are in the old frame, like the loop landmarks.
    LandmarkBookEntry* record = book.find(id);
    if (record == nullptr || !record->drifts_with_vehicle ||
        t_us - record->last_seen_us >= min_age_us) {
      continue;
    }
    state.setValue(v, fit->apply(state.value(v)));
    record->first_estimate = fit->apply(record->first_estimate);
    record->yaw_direction = moveYawDirection(record->yaw_direction, *fit);
  }
  return static_cast<int>(loop_ids_.size());
}

}  // namespace cvslam
