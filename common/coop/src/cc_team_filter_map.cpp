// CcTeamFilter's association (§6.3.1 types) and k-nearest map management over the joint map
// (cc_team_filter.h, steps 2, 3 and the bookkeeping after 5).

#include <algorithm>
#include <cmath>
#include <limits>

#include "cc_team_filter_impl.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/slam/landmark_lifecycle.h"
#include "cvslam/vision/descriptor_distance.h"

namespace cvslam::coop {

namespace {

bool contains(const std::vector<int64_t>& sorted, int64_t id) {
  return std::binary_search(sorted.begin(), sorted.end(), id);
}

VariableKey landmarkKey(int64_t id) {
  return VariableKey::landmark(static_cast<uint64_t>(id));
}

}  // namespace

void CcTeamFilter::Impl::restartDriftedFirstEstimates(double max_drift_m) {
  for (const StateVariable& sv : state.variables()) {
    if (sv.key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(sv.key.id);
    const Eigen::Vector3d p = state.value(sv);
    for (auto& [agent, v] : vehicles) {
      LandmarkBookEntry* r = v->book.find(id);
      if (r != nullptr && (p - r->first_estimate).norm() > max_drift_m) r->first_estimate = p;
    }
  }
}

bool CcTeamFilter::Impl::activeForAnother(int64_t id, int agent_id) const {
  for (const auto& [other, v] : vehicles) {
    if (other != agent_id && contains(v->active, id)) return true;
  }
  return false;
}

const LandmarkBookEntry* CcTeamFilter::Impl::recordOf(int64_t id) const {
  for (const auto& [agent, v] : vehicles) {
    if (const LandmarkBookEntry* r = v->book.find(id)) return r;
  }
  return nullptr;
}

void CcTeamFilter::Impl::archiveEverywhere(int64_t id, int64_t t_us) {
  std::optional<LandmarkBookEntry> merged;
  for (auto& [agent, v] : vehicles) {
    std::optional<LandmarkBookEntry> r = v->book.remove(id);
    if (!r) continue;
    if (!merged) {
      merged = std::move(r);
    } else {
      merged->last_seen_us = std::max(merged->last_seen_us, r->last_seen_us);
    }
  }
  archiveLandmark(state, archive, id, std::move(merged), t_us);
}

void CcTeamFilter::Impl::noteObserver(int64_t id, int agent_id, const StereoObservation& obs) {
  auto [it, fresh] = landmarks.try_emplace(id);
  CcLandmarkInfo& info = it->second;
  if (fresh) {
    info.index = obs.index;
    info.descriptor = obs.descriptor;
    by_index[obs.index].push_back(id);
  }
  auto pos = std::lower_bound(info.observers.begin(), info.observers.end(), agent_id);
  if (pos == info.observers.end() || *pos != agent_id) info.observers.insert(pos, agent_id);
}

int64_t CcTeamFilter::Impl::jointOf(CcVehicle& v, const StereoObservation& obs,
                                    const CcTeamFilterOptions& o,
                                    const std::vector<int64_t>& used) {
  auto known = v.joint_of_local.find(obs.landmark_id);
  if (known != v.joint_of_local.end()) return known->second;
  // A landmark new to this UAV: another UAV's landmark of the same feature index whose
  // descriptor (as DC's check, coop.max_descriptor_distance) and position agree, else new.
  const vehicle_model::Pose x = vehicle_model::pose(state, *state.find(v.key));
  Eigen::Vector3d p_seen;
  const bool triangulated = v.camera.triangulate(obs.z, x, &p_seen).ok();
  int64_t best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  auto candidates = by_index.find(obs.index);
  if (triangulated && candidates != by_index.end()) {
    for (int64_t id : candidates->second) {
      const CcLandmarkInfo& info = landmarks.at(id);
      if (std::binary_search(info.observers.begin(), info.observers.end(), v.agent_id)) continue;
      if (std::find(used.begin(), used.end(), id) != used.end()) continue;
      double d = 0.0;
      if (!info.descriptor.empty() && info.descriptor.size() == obs.descriptor.size()) {
        d = std::sqrt(static_cast<double>(
            vision::distanceL2Squared(info.descriptor.data(), obs.descriptor.data(),
                                      static_cast<int>(obs.descriptor.size()))));
        if (d > o.max_descriptor_distance) continue;
      }
      Eigen::Vector3d p_map;
      if (const StateVariable* lm = state.find(landmarkKey(id))) {
        p_map = state.value(*lm);
      } else if (const ArchivedLandmark* a = archive.find(id)) {
        p_map = a->p_LinN;
      } else {
        continue;  // named but never initialised
      }
      if ((p_seen - p_map).norm() > o.max_association_distance_m) continue;
      if (d < best_distance) best_distance = d, best = id;
    }
  }
  const int64_t joint = best >= 0 ? best : next_fresh_id++;
  v.joint_of_local.emplace(obs.landmark_id, joint);
  return joint;
}

void CcTeamFilter::Impl::associate(CcVehicle& v, const CcObservationBatch& batch,
                                   const CcTeamFilterOptions& o) {
  frame.t_us = batch.t_us;
  frame.observations = batch.frame.observations;
  types.assign(frame.observations.size(), 3);
  std::vector<int64_t> used;
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    StereoObservation& obs = frame.observations[i];
    if (o.association == CcAssociation::kLocalIds && obs.landmark_id >= 0) {
      obs.landmark_id = jointOf(v, obs, o, used);
      used.push_back(obs.landmark_id);
    }
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    auto info = landmarks.find(id);
    if (info == landmarks.end()) continue;  // type 3
    const std::vector<int>& seen_by = info->second.observers;
    types[i] = std::binary_search(seen_by.begin(), seen_by.end(), v.agent_id) ? 1 : 2;
    if (!state.has(landmarkKey(id)) || v.book.find(id) != nullptr) continue;
    // A state landmark new to this UAV's book: the landmark's own first estimate and OC yaw
    // direction (one per landmark, shared by every observer), the latest time anyone saw it
    // (so that an old landmark of another UAV is a loop landmark here: loops across UAVs).
    const LandmarkBookEntry* r = recordOf(id);
    if (r == nullptr) continue;
    LandmarkBookEntry copy = *r;
    copy.drifts_with_vehicle = false;
    for (const auto& [agent, other] : vehicles) {
      if (const LandmarkBookEntry* e = other->book.find(id))
        copy.last_seen_us = std::max(copy.last_seen_us, e->last_seen_us);
    }
    v.book.add(id, std::move(copy));
  }
}

void CcTeamFilter::Impl::manageMap(CcVehicle& v, int64_t t_us, double reactivation_min_age_s,
                                   FrameReport* r) {
  const Eigen::Vector3d m_star = frameVirtualPoint(map_manager, v.camera, state, v.key, frame);
  std::vector<int64_t> observed;
  observed.reserve(frame.observations.size());
  for (const StereoObservation& obs : frame.observations) {
    if (obs.landmark_id >= 0) observed.push_back(obs.landmark_id);
  }
  std::sort(observed.begin(), observed.end());
  // Candidates: this UAV's active landmarks and the state landmarks it observes now (in state
  // order), then the archived ones it observes now (as VisualInertialSlam, §5.8).
  std::vector<MapCandidate> candidates;
  for (const StateVariable& sv : state.variables()) {
    if (sv.key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(sv.key.id);
    const bool seen = contains(observed, id);
    if (!seen && !contains(v.active, id)) continue;
    candidates.push_back({id, state.value(sv), seen});
  }
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    const ArchivedLandmark* a = archive.find(id);
    if (a != nullptr &&
        static_cast<double>(t_us - a->archived_us) * 1e-6 >= reactivation_min_age_s) {
      candidates.push_back({id, a->p_LinN, true, true});
    }
  }
  const std::vector<int64_t> keep = map_manager.select(candidates, m_star);
  // A landmark that leaves this UAV's k nearest is archived unless another UAV keeps it.
  for (const MapCandidate& cand : candidates) {
    if (contains(keep, cand.landmark_id) || !state.has(landmarkKey(cand.landmark_id))) continue;
    if (activeForAnother(cand.landmark_id, v.agent_id)) continue;
    archiveEverywhere(cand.landmark_id, t_us);
    ++r->archived;
  }
  for (int64_t id : keep) {
    if (state.has(landmarkKey(id))) continue;
    if (reactivateLandmark(state, v.book, archive, id)) ++r->reactivated;
  }
  v.active = keep;
}

void CcTeamFilter::Impl::afterInitialisation(CcVehicle& v, std::size_t first_new) {
  const std::vector<StateVariable>& vars = state.variables();
  for (std::size_t i = first_new; i < vars.size(); ++i) {
    if (vars[i].key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(vars[i].key.id);
    v.active.insert(std::upper_bound(v.active.begin(), v.active.end(), id), id);
    if (const LandmarkBookEntry* r = v.book.find(id)) {
      StereoObservation named;
      named.index = r->index;
      named.descriptor = r->descriptor;
      noteObserver(id, v.agent_id, named);
    }
  }
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0 || !(state.has(landmarkKey(id)) || archive.contains(id))) continue;
    noteObserver(id, v.agent_id, obs);
  }
}

}  // namespace cvslam::coop
