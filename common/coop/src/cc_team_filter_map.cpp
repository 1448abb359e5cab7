// CcTeamFilter's association (§6.3.1 types) and k-nearest map management over the joint map
// (cc_team_filter.h, steps 2, 3 and the bookkeeping after 5).

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "cc_team_filter_impl.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/slam/landmark_lifecycle.h"
#include "cvslam/slam/observability_constraint.h"
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

int64_t CcTeamFilter::Impl::lastSeen(int64_t id) const {
  int64_t t = std::numeric_limits<int64_t>::min();
  for (const auto& [agent, v] : vehicles) {
    if (const LandmarkBookEntry* e = v->book.find(id)) t = std::max(t, e->last_seen_us);
  }
  return t;
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

void CcTeamFilter::Impl::archiveEverywhere(int64_t id, int64_t t_us, const SlamOptions& slam) {
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
  std::vector<Eigen::Vector3d> keep_near;
  if (slam.held_eviction == SlamOptions::HeldEviction::kNearest) {
    for (const auto& [agent, v] : vehicles)
      if (v->m_star) keep_near.push_back(*v->m_star);
  }
  archiveLandmark(state, archive, id, std::move(merged), t_us, slam.held_landmarks, keep_near,
                  slam.anchor_landmarks);
}

double CcTeamFilter::Impl::positionSigma(const CcVehicle& v) const {
  const StateVariable* sv = state.find(v.key);
  return std::sqrt(state.covarianceOf(*sv).topLeftCorner<3, 3>().trace() / 3.0);
}

bool CcTeamFilter::Impl::rendezvous(const CcVehicle& v, int other, int64_t t_us,
                                    const CcTeamFilterOptions& o) const {
  if (o.rendezvous_min_sigma_m <= 0.0) return false;
  const auto max_age_us = static_cast<int64_t>(o.slam.slam.loop_closure_min_age_s * 1e6);
  auto it = contact.find({std::min(v.agent_id, other), std::max(v.agent_id, other)});
  if (it != contact.end() && t_us - it->second < max_age_us) return false;
  auto peer = vehicles.find(other);
  const double sigma = positionSigma(v);
  // rendezvous_sigma_ratio 0 (the default): UAVs that drifted alike meet this way too.
  return sigma >= o.rendezvous_min_sigma_m &&
         (peer == vehicles.end() ||
          sigma >= o.rendezvous_sigma_ratio * positionSigma(*peer->second));
}

bool CcTeamFilter::Impl::meetsAnotherMap(const CcVehicle& v, const std::vector<int>& observers,
                                         int64_t t_us, const CcTeamFilterOptions& o) const {
  for (int other : observers) {
    if (other != v.agent_id && rendezvous(v, other, t_us, o)) return true;
  }
  return false;
}

void CcTeamFilter::Impl::meetReentered(const CcVehicle& v, const std::vector<int64_t>& loop,
                                       int64_t t_us, const CcTeamFilterOptions& o) {
  // thesis_loop seed 2: UAV1 met UAV2's map at 78 s through one held landmark, 5 m off, and the
  // plain EKF update of that frame moved UAV1 5.2 m and UAV2 3.5 m; at 80 s both were 3 m off
  // at σ 1.4 m (NEES 74 and 132), and 5-12 m off until UAV1's loop at 199 s.
  // associate() met only landmarks in the state then, so none of these is in `meet` yet.
  for (int64_t id : reentered) {
    if (std::binary_search(loop.begin(), loop.end(), id)) continue;
    auto info = landmarks.find(id);
    if (info != landmarks.end() && meetsAnotherMap(v, info->second.observers, t_us, o))
      meet.push_back(id);
  }
  std::sort(meet.begin(), meet.end());
}

Eigen::Vector3d CcTeamFilter::Impl::meetShift(const CcVehicle& v) const {
  const vehicle_model::Pose x = vehicle_model::pose(state, *state.find(v.key));
  std::vector<double> d[3];
  for (const StereoObservation& obs : frame.observations) {
    if (!std::binary_search(meet.begin(), meet.end(), obs.landmark_id)) continue;
    const StateVariable* lm = state.find(landmarkKey(obs.landmark_id));
    Eigen::Vector3d p_seen;
    if (lm == nullptr || !v.camera.triangulate(obs.z, x, &p_seen).ok()) continue;
    const Eigen::Vector3d diff = state.value(*lm) - p_seen;
    for (int i = 0; i < 3; ++i) d[i].push_back(diff(i));
  }
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (d[i].empty()) continue;
    auto mid = d[i].begin() + static_cast<std::ptrdiff_t>(d[i].size() / 2);
    std::nth_element(d[i].begin(), mid, d[i].end());
    shift(i) = *mid;
  }
  return shift;
}

void CcTeamFilter::Impl::followCorrectionEverywhere(const Eigen::VectorXd& mean_before) {
  for (auto& [agent_id, w] : vehicles) followCorrection(state, mean_before, w->key, &w->book);
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

bool CcTeamFilter::Impl::withinGate(const CcVehicle& v, const StereoObservation& obs, int64_t id,
                                    double chi2) {
  // The observation as one of landmark `id`, linearised at the joint estimate: the innovation
  // and its covariance H P Hᵀ + R over this vehicle's and the landmark's correlated blocks.
  gate_frame.t_us = frame.t_us;
  gate_frame.observations.assign(1, obs);
  gate_frame.observations.front().landmark_id = id;
  if (!v.updater
           .linearise(state, v.book, gate_frame, StereoUpdater::Selection::kOnlyListed, {id},
                      StereoUpdater::Jacobians::kPlain, 1.0, &gate_batch)
           .ok() ||
      gate_batch.rows() != 4) {
    return false;  // behind the camera
  }
  gate_batch.multiplyByHt(state.covariance(), &gate_PHt);
  gate_batch.multiplyH(gate_PHt, &gate_S);
  const Eigen::Matrix4d S = gate_S + gate_batch.R();
  const Eigen::LLT<Eigen::Matrix4d> llt(S);
  if (llt.info() != Eigen::Success) return false;
  return llt.matrixL().solve(Eigen::Vector4d(gate_batch.residual())).squaredNorm() <= chi2;
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
      if (state.has(landmarkKey(id))) {
        if (!withinGate(v, obs, id, o.association_gate_chi2)) continue;
      } else if (const ArchivedLandmark* a = archive.find(id)) {
        if ((p_seen - a->p_LinN).norm() > o.max_association_distance_m) continue;
      } else {
        continue;  // named but never initialised
      }
      if (d < best_distance) best_distance = d, best = id;
    }
  }
  const int64_t joint = best >= 0 ? best : next_fresh_id++;
  v.joint_of_local.emplace(obs.landmark_id, joint);
  if (best < 0) {
    made_from.emplace(joint, std::make_pair(v.agent_id, obs.landmark_id));
  } else if (auto from = made_from.find(best); from != made_from.end()) {
    if (cross.size() >= CcTeamFilter::kMaxCrossAssociations) cross.erase(cross.begin());
    cross.push_back({v.agent_id, obs.landmark_id, from->second.first, from->second.second});
  }
  return joint;
}

void CcTeamFilter::Impl::associate(CcVehicle& v, const CcObservationBatch& batch,
                                   const CcTeamFilterOptions& o) {
  frame.t_us = batch.t_us;
  frame.observations = batch.frame.observations;
  types.assign(frame.observations.size(), 3);
  meet.clear();
  std::vector<int64_t> used;
  std::vector<std::size_t> anonymous;
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    StereoObservation& obs = frame.observations[i];
    if (o.association == CcAssociation::kLocalIds && obs.landmark_id < 0) {
      // A stereo match the agent did not map: a landmark made of it would carry no agent id,
      // so the agent's later observations of that feature (under the id it gives it when it
      // maps it) could never be associated to it. The agent's own map decides what becomes a
      // landmark (its confirmation across frames included); the joint map follows it.
      anonymous.push_back(i);
      continue;
    }
    if (o.association == CcAssociation::kLocalIds) {
      obs.landmark_id = jointOf(v, obs, o, used);
      used.push_back(obs.landmark_id);
    }
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    auto info = landmarks.find(id);
    if (info == landmarks.end()) continue;  // type 3
    const std::vector<int>& seen_by = info->second.observers;
    types[i] = std::binary_search(seen_by.begin(), seen_by.end(), v.agent_id) ? 1 : 2;
    if (!state.has(landmarkKey(id))) continue;
    if (LandmarkBookEntry* own = v.book.find(id)) {
      // A loop landmark is one nobody saw for loop_closure_min_age_s: a landmark another UAV
      // kept observing is no loop for this one (it is tied to it through the joint state).
      own->last_seen_us = std::max(own->last_seen_us, lastSeen(id));
      continue;
    }
    // A state landmark new to this UAV's book: the landmark's own first estimate and OC yaw
    // direction (one per landmark, shared by every observer), the latest time anyone saw it
    // (so that an old landmark of another UAV is a loop landmark here: loops across UAVs).
    const LandmarkBookEntry* r = recordOf(id);
    if (r == nullptr) continue;
    LandmarkBookEntry copy = *r;
    copy.drifts_with_vehicle = false;
    copy.last_seen_us = lastSeen(id);
    // A rendezvous: the first contact of this UAV with another's map while it is uncertain
    // (cc_team_filter.h, runRecipe).
    if (meetsAnotherMap(v, seen_by, batch.t_us, o)) meet.push_back(id);
    v.book.add(id, std::move(copy));
  }
  std::sort(meet.begin(), meet.end());
  for (auto it = anonymous.rbegin(); it != anonymous.rend(); ++it) {
    frame.observations.erase(frame.observations.begin() + static_cast<std::ptrdiff_t>(*it));
    types.erase(types.begin() + static_cast<std::ptrdiff_t>(*it));
  }
}

Status CcTeamFilter::Impl::manageMap(CcVehicle& v, int64_t t_us, const SlamOptions& slam,
                                     double reactivation_inflation, FrameReport* r) {
  const Eigen::Vector3d m_star = frameVirtualPoint(map_manager, v.camera, state, v.key, frame);
  v.m_star = m_star;
  reentered.clear();
  const std::vector<int64_t> observed = observedLandmarkIds(frame);
  // Candidates: this UAV's active landmarks and the state landmarks it observes now (in state
  // order), then the archived ones it observes now (§5.8).
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
    if (a == nullptr || !mayReenter(state, id, *a, t_us, slam)) continue;
    // A held landmark comes back exactly to any UAV: its correlations with every vehicle
    // stayed in the joint state.
    auto info = landmarks.find(id);
    if (isHeld(state, id) || info == landmarks.end() || info->second.mapped_by == v.agent_id) {
      candidates.push_back({id, a->p_LinN, true, true});
    } else {
      // Another UAV's archived landmark is not re-activated here: entering as an independent
      // absolute prior it would hand this UAV, and through the joint state the team, the
      // information the landmark already gave when it was mapped (measured on team3_aerial:
      // vehicle NEES 70 instead of 40). This UAV maps it anew (step 5), correlated with itself.
      archive.take(id);
    }
  }
  const std::vector<int64_t> keep = map_manager.select(candidates, m_star);
  // A landmark that leaves this UAV's k nearest is archived unless another UAV keeps it.
  for (const MapCandidate& cand : candidates) {
    if (contains(keep, cand.landmark_id) || !state.has(landmarkKey(cand.landmark_id))) continue;
    if (activeForAnother(cand.landmark_id, v.agent_id)) continue;
    archiveEverywhere(cand.landmark_id, t_us, slam);
    ++r->archived;
  }
  // Re-entry as in single mode (SlamOptions::Reentry): a held landmark exactly; remap: mapped
  // anew in step 5; intersection: by covariance intersection with the whole joint state
  // (reactivation_intersection.h; the bound holds for any correlation with any UAV, at the
  // price of scaling every UAV's prior by 1/ω). Independent re-entry would hand this UAV (and,
  // through it, the team) position information nobody has, since in the joint map the landmark
  // was tied to every UAV that saw it: its covariance gets the UAV's own position covariance
  // on top (reactivation_inflation), so that mostly what it says relative to the UAV is taken.
  const StateVariable* veh = state.find(v.key);
  const Eigen::Matrix3d P_pp = state.covarianceOf(*veh).topLeftCorner<3, 3>();
  std::vector<int64_t> intersected;
  v.active.clear();
  for (int64_t id : keep) {
    if (!state.has(landmarkKey(id))) {
      const ArchivedLandmark* a = archive.find(id);
      if (a == nullptr || isHeld(state, id)) {  // held: back exactly (re-keyed, no inflation)
        if (reactivateLandmark(state, v.book, archive, id)) reentered.push_back(id);
      } else {
        switch (reentryOf(*a, t_us, slam)) {
          case SlamOptions::Reentry::kRemap:
            archive.take(id);  // mapped anew in step 5 (afterInitialisation makes it active)
            continue;
          case SlamOptions::Reentry::kIntersection:
            intersected.push_back(id);
            break;
          case SlamOptions::Reentry::kIndependent:
            if (reactivateLandmark(state, v.book, archive, id, reactivation_inflation * P_pp))
              reentered.push_back(id);
            break;
        }
      }
    }
    v.active.push_back(id);
  }
  Status s = Status::Ok();
  if (!intersected.empty()) {
    // ω for the team: the objective (slam.reactivation_objective) over every UAV's block, since
    // all pay 1/ω.
    std::vector<VariableKey> team;
    for (const auto& [id, other] : vehicles) team.push_back(other->key);
    ReactivationReport rep;
    s = reactivation.reactivate(state, v.book, archive, intersected, v.updater, frame, &rep, team);
    for (int64_t id : intersected)
      if (state.has(landmarkKey(id))) reentered.push_back(id);
  }
  r->reactivated += static_cast<int>(reentered.size());
  std::sort(reentered.begin(), reentered.end());
  return s;
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
      landmarks[id].mapped_by = v.agent_id;
    }
  }
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0 || !(state.has(landmarkKey(id)) || archive.contains(id))) continue;
    noteObserver(id, v.agent_id, obs);
    // Shared outside a pending loop: the two maps are in contact.
    if (v.book.isPendingLoop(id) || v.book.find(id) == nullptr) continue;
    for (int other : landmarks.at(id).observers) {
      if (other != v.agent_id)
        contact[{std::min(other, v.agent_id), std::max(other, v.agent_id)}] = frame.t_us;
    }
  }
}

}  // namespace cvslam::coop
