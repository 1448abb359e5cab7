// CcTeamFilter: vehicles, the per-batch recipe, estimates (cc_team_filter.h). The association
// and the map management over the joint map are in cc_team_filter_map.cpp.

#include "cvslam/coop/cc_team_filter.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>

#include "cc_team_filter_impl.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"

namespace cvslam::coop {

CcTeamFilter::CcTeamFilter(const CcTeamFilterOptions& options)
    : o_(options), impl_(std::make_unique<Impl>()) {
  if (o_.association == CcAssociation::kLocalIds) {
    o_.slam.slam.second_order_noise = o_.image_second_order_noise;
    o_.slam.slam.second_order_mean = o_.image_second_order_mean;
    o_.slam.slam.pixel_sigma = o_.image_pixel_sigma;
  }
  impl_->map_manager = KNearestMapManager(o_.slam.map);
  // The joint map's re-entry bookkeeping (cc_team_filter_map.cpp) has no path for landmarks
  // taken back out: the ground station always intersects, with ω by the configured objective.
  ReactivationOptions reactivation = o_.slam.slam.intersection;
  reactivation.remap_without_gain = false;
  impl_->reactivation = ReactivationIntersection(reactivation);
  impl_->state.setErrorChart(o_.slam.slam.error_chart);
  Expected<UpdatePolicy> policy = o_.slam.filter.policy();
  if (policy.ok()) {
    impl_->policy = *policy;
  } else {
    impl_->policy_status = policy.status();
  }
}

CcTeamFilter::~CcTeamFilter() = default;
CcTeamFilter::CcTeamFilter(CcTeamFilter&&) noexcept = default;
CcTeamFilter& CcTeamFilter::operator=(CcTeamFilter&&) noexcept = default;

const SlamState& CcTeamFilter::state() const {
  return impl_->state;
}

bool CcTeamFilter::hasVehicle(int agent_id) const {
  return impl_->vehicles.count(agent_id) > 0;
}

std::vector<int> CcTeamFilter::vehicles() const {
  std::vector<int> ids;
  for (const auto& [id, v] : impl_->vehicles) ids.push_back(id);
  return ids;
}

std::vector<CcCrossAssociation> CcTeamFilter::takeCrossAssociations() {
  std::vector<CcCrossAssociation> out;
  out.swap(impl_->cross);
  return out;
}

std::vector<int64_t> CcTeamFilter::activeLandmarks(int agent_id) const {
  auto it = impl_->vehicles.find(agent_id);
  return it == impl_->vehicles.end() ? std::vector<int64_t>{} : it->second->active;
}

Status CcTeamFilter::addVehicle(int agent_id, const StereoCamera& camera, int64_t t_us,
                                const Eigen::VectorXd& x_v, const Eigen::MatrixXd& P_v,
                                const InsPropagatorOptions* ins) {
  if (!impl_->policy_status.ok()) return impl_->policy_status;
  // The vehicle's IMU (noise densities); the joint filter's own attitude parametrisation.
  InsPropagatorOptions ins_options = ins != nullptr ? *ins : o_.slam.ins;
  ins_options.attitude = o_.slam.ins.attitude;
  if (ins_options.estimate_imu_bias != o_.slam.ins.estimate_imu_bias) {
    return Status::Error(
        "addVehicle: the vehicle's ins.estimate_imu_bias differs from the "
        "ground station's");
  }
  const int n = InsPropagator(ins_options).stateSize();
  if (x_v.size() != n || P_v.rows() != n || P_v.cols() != n) {
    return Status::Error("addVehicle: the vehicle state must have " + std::to_string(n) +
                         " entries");
  }
  if (!x_v.allFinite() || !P_v.allFinite()) {
    return Status::Error("addVehicle: the vehicle state is not finite");
  }
  auto it = impl_->vehicles.find(agent_id);
  if (it == impl_->vehicles.end() && static_cast<int>(impl_->vehicles.size()) >= o_.max_vehicles) {
    return Status::Error("addVehicle: already " + std::to_string(o_.max_vehicles) +
                         " vehicles (cc.max_vehicles)");
  }
  if (it == impl_->vehicles.end()) {
    it = impl_->vehicles
             .emplace(agent_id,
                      std::make_unique<CcVehicle>(agent_id, camera, ins_options, o_.slam.slam))
             .first;
  } else {
    // Re-initialisation (§6.3.1 known pose, e.g. the agent's own estimate after a restart):
    // the block is replaced, uncorrelated; the UAV's map bookkeeping is kept.
    CovarianceHelper::marginalize(impl_->state, it->second->key);
    it->second->has_batch = false;
  }
  CcVehicle& v = *it->second;
  if (auto o = impl_->oracles.find(agent_id); o != impl_->oracles.end()) v.setOracle(o->second);
  // x_v, P_v in the Euler layout (messages, setups); the block takes the configured attitude.
  if (Status s = vehicle_model::addVehicle(impl_->state, v.key, x_v, P_v, ins_options.attitude);
      !s.ok()) {
    return s;
  }
  v.propagation.reset(t_us);
  v.book.setVehicleYawDirection(
      vehicle_model::yawDirection(vehicle_model::pose(impl_->state, *impl_->state.find(v.key)), n));
  stats_.agents[agent_id];
  ++map_version_;
  return Status::Ok();
}

void CcTeamFilter::setLinearisationOracle(int agent_id, const LinearisationOracle* oracle) {
  impl_->oracles[agent_id] = oracle;
  // The ideal EKF's Jacobians are at the truth, which an update does not move: its chart is the
  // additive one whatever the configuration (docs/results/ideal_ekf.md). Set before the first
  // vehicle enters, the whole state has it.
  const bool any_oracle = std::any_of(impl_->oracles.begin(), impl_->oracles.end(),
                                      [](const auto& o) { return o.second != nullptr; });
  impl_->state.setErrorChart(any_oracle ? ErrorChart::kAdditive : o_.slam.slam.error_chart);
  if (auto it = impl_->vehicles.find(agent_id); it != impl_->vehicles.end()) {
    it->second->setOracle(oracle);
  }
}

Status CcTeamFilter::removeVehicle(int agent_id) {
  auto it = impl_->vehicles.find(agent_id);
  if (it == impl_->vehicles.end()) {
    return Status::Error("removeVehicle: no vehicle " + std::to_string(agent_id));
  }
  const std::vector<int64_t> active = it->second->active;
  const int64_t t_us = it->second->propagation.time();
  if (Status s = CovarianceHelper::marginalize(impl_->state, it->second->key); !s.ok()) return s;
  impl_->vehicles.erase(it);
  // Its landmarks stay in the joint map: archived unless another UAV keeps them active.
  for (int64_t id : active) {
    if (!impl_->activeForAnother(id, agent_id)) impl_->archiveEverywhere(id, t_us, o_.slam.slam);
  }
  ++map_version_;
  return Status::Ok();
}

Expected<VehicleEstimate> CcTeamFilter::estimate(int agent_id) const {
  auto it = impl_->vehicles.find(agent_id);
  if (it == impl_->vehicles.end()) {
    return Status::Error("estimate: no vehicle " + std::to_string(agent_id));
  }
  const StateVariable* v = impl_->state.find(it->second->key);
  VehicleEstimate e;
  e.t_us = it->second->propagation.time();
  vehicle_model::eulerLayout(impl_->state, *v, &e.x_v, &e.P_v);  // the messages' layout
  return e;
}

std::vector<MapLandmark> CcTeamFilter::map() const {
  std::vector<MapLandmark> out;
  for (const StateVariable& v : impl_->state.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    MapLandmark m;
    m.id = static_cast<int64_t>(v.key.id);
    auto info = impl_->landmarks.find(m.id);
    if (info != impl_->landmarks.end()) m.index = info->second.index;
    m.p_LinN = impl_->state.value(v);
    m.covariance = impl_->state.covarianceOf(v);
    m.in_state = true;
    out.push_back(m);
  }
  for (const auto& [id, a] : impl_->archive.all()) {
    out.push_back({id, a.index, a.p_LinN, a.covariance, false});
  }
  std::sort(out.begin(), out.end(),
            [](const MapLandmark& a, const MapLandmark& b) { return a.id < b.id; });
  return out;
}

std::string refusalKey(CcRefusal refusal, const std::string& defect) {
  switch (refusal) {
    case CcRefusal::kNone:
      return "none";
    case CcRefusal::kUnknownAgent:
      return "unknown_agent";
    case CcRefusal::kStale:
      return "stale";
    case CcRefusal::kInvalid:
      return "invalid_" + (defect.empty() ? std::string("batch") : defect);
    case CcRefusal::kPropagation:
      return "propagation";
    case CcRefusal::kUpdate:
      return "update";
  }
  return "unknown";
}

std::string CcTeamStatistics::refusalSummary() const {
  std::string out;
  for (const auto& [id, c] : agents) {
    if (c.refused.empty()) continue;
    out += (out.empty() ? "UAV" : "; UAV") + std::to_string(id);
    bool first = true;
    for (const auto& [key, n] : c.refused) {
      out += (first ? " " : ", ") + key + " " + std::to_string(n);
      first = false;
    }
  }
  return out.empty() ? "none" : out;
}

namespace {

/// Counts a refused batch by its reason and says why.
Status refuse(CcTeamStatistics* stats, CcStepReport* r, CcRefusal refusal, const std::string& why,
              const std::string& defect = "") {
  switch (refusal) {
    case CcRefusal::kUnknownAgent:
      ++stats->rejected_unknown_agent;
      break;
    case CcRefusal::kStale:
      ++stats->rejected_stale;
      break;
    case CcRefusal::kInvalid:
      ++stats->rejected_invalid;
      break;
    case CcRefusal::kPropagation:
      ++stats->rejected_propagation;
      break;
    case CcRefusal::kUpdate:
      ++stats->rejected_update;
      break;
    case CcRefusal::kNone:
      break;
  }
  if (auto it = stats->agents.find(r->agent_id); it != stats->agents.end()) {
    ++it->second.rejected;
    ++it->second.refused[refusalKey(refusal, defect)];
  }
  r->accepted = false;
  r->refusal = refusal;
  r->defect = defect;
  r->reason = why;
  return Status::Error("batch of agent " + std::to_string(r->agent_id) +
                       " at t=" + std::to_string(r->t_us) + " µs refused: " + why);
}

/// Samples linearly interpolated strictly between `a` and `b`, spaced at most `period_us`.
std::vector<ImuSample> bridge(const ImuSample& a, const ImuSample& b, int64_t period_us) {
  std::vector<ImuSample> out;
  const int64_t gap = b.t_us - a.t_us;
  const int64_t steps = (gap + period_us - 1) / period_us;
  for (int64_t k = 1; k < steps; ++k) out.push_back(interpolateImu(a, b, a.t_us + gap * k / steps));
  return out;
}

/// The batch's own sample period (median spacing), else `fallback_us`.
int64_t samplePeriod(const std::vector<ImuSample>& imu, int64_t fallback_us) {
  std::vector<int64_t> d;
  for (std::size_t i = 1; i < imu.size(); ++i) d.push_back(imu[i].t_us - imu[i - 1].t_us);
  if (d.empty()) return fallback_us;
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return std::max<int64_t>(1, std::min(d[d.size() / 2], fallback_us));
}

}  // namespace

Status CcTeamFilter::processBatch(const CcObservationBatch& batch, CcStepReport* report) {
  const auto start = std::chrono::steady_clock::now();
  CcStepReport local;
  CcStepReport& r = report != nullptr ? *report : local;
  r = CcStepReport();
  r.agent_id = batch.agent_id;
  r.t_us = batch.t_us;
  auto it = impl_->vehicles.find(batch.agent_id);
  if (it == impl_->vehicles.end()) {
    return refuse(&stats_, &r, CcRefusal::kUnknownAgent, "unknown agent");
  }
  CcVehicle& v = *it->second;
  std::string defect;
  if (Status s = validateBatch(batch, 1e5, &defect); !s.ok()) {
    return refuse(&stats_, &r, CcRefusal::kInvalid, s.message(), defect);
  }
  if (batch.t_us < v.propagation.time() || (v.has_batch && batch.t_us <= v.last_batch_us)) {
    return refuse(&stats_, &r, CcRefusal::kStale, "not after the vehicle's last batch");
  }
  // A feature-level agent names each landmark by its true id, its feature index; an image
  // agent by its own local ids. Taken for true ids, those would join unrelated landmarks of
  // different UAVs, silently: refused instead, with what to do.
  if (o_.association == CcAssociation::kTrueIds) {
    for (const StereoObservation& obs : batch.frame.observations) {
      if (obs.landmark_id >= 0 && obs.landmark_id != obs.index) {
        return refuse(&stats_, &r, CcRefusal::kInvalid,
                      "landmark " + std::to_string(obs.landmark_id) + " has feature index " +
                          std::to_string(obs.index) +
                          ": the agent names its landmarks by its own ids (images), the ground "
                          "station by true ids (--association local_ids, cc.association)",
                      "local_ids");
      }
    }
  }
  // 1. Propagate (samples the vehicle's buffer already covers are older than its state:
  // the first batch after a (re-)initialisation may repeat them). A gap before the batch's
  // first new sample is what a batch lost on the way leaves: bridged when short, checked
  // before anything changes.
  std::vector<ImuSample> samples;
  samples.reserve(batch.imu.size());
  for (const ImuSample& s : batch.imu)
    if (s.t_us > v.propagation.lastSampleTime()) samples.push_back(s);
  const int64_t last_us = v.propagation.lastSampleTime();
  const int64_t first_us = samples.empty() ? batch.t_us : samples.front().t_us;
  const double gap_s = 1e-6 * static_cast<double>(first_us - last_us);
  const double max_dt = v.propagator.options().max_dt;
  const bool has_last = v.propagation.hasSamples();
  if (has_last && gap_s > max_dt) {
    if (gap_s > o_.max_imu_gap_s || samples.empty()) {
      return refuse(&stats_, &r, CcRefusal::kPropagation,
                    "IMU gap of " + std::to_string(gap_s) + " s before the batch exceeds " +
                        "cc.max_imu_gap_s " + std::to_string(o_.max_imu_gap_s) + " s");
    }
    const int64_t period = samplePeriod(samples, std::llround(0.5 * max_dt * 1e6));
    std::vector<ImuSample> filled = bridge(v.propagation.lastSample(), samples.front(), period);
    samples.insert(samples.begin(), filled.begin(), filled.end());
    r.imu_gap_bridged_s = gap_s;
  }
  for (const ImuSample& s : samples) {
    if (Status st = v.propagation.addImu(s); !st.ok()) {
      return refuse(&stats_, &r, CcRefusal::kPropagation, st.message());
    }
    v.noise_monitor.add(s);
  }
  if (v.noise_monitor.ready()) {
    v.propagator.setMeasuredNoiseDensities(v.noise_monitor.gyroDensity(),
                                           v.noise_monitor.accelDensity());
  }
  if (Status s = v.propagation.propagateTo(batch.t_us, v.propagator, impl_->policy, v.key,
                                           impl_->state, v.book);
      !s.ok()) {
    return refuse(&stats_, &r, CcRefusal::kPropagation, s.message());
  }
  v.has_batch = true;
  v.last_batch_us = batch.t_us;
  if (r.imu_gap_bridged_s > 0.0) {
    CcAgentCounts& c = stats_.agents[batch.agent_id];
    ++c.imu_gaps_bridged;
    c.imu_gap_bridged_s += r.imu_gap_bridged_s;
  }
  if (Status s = runRecipe(v, batch, &r); !s.ok()) {
    ++map_version_;  // the vehicle moved
    return refuse(&stats_, &r, CcRefusal::kUpdate, s.message());
  }
  r.accepted = true;
  r.state_size = impl_->state.size();
  r.vehicles = static_cast<int>(impl_->vehicles.size());
  r.step_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ++stats_.batches;
  stats_.step_ms.push_back(r.step_ms);
  stats_.max_state_size = std::max(stats_.max_state_size, r.state_size);
  CcAgentCounts& c = stats_.agents[batch.agent_id];
  ++c.batches;
  c.observations += static_cast<long>(batch.frame.observations.size());
  c.type1 += r.type1;
  c.type2 += r.type2;
  c.type3 += r.type3;
  c.loop_closures += r.frame.loop_closure ? 1 : 0;
  ++map_version_;
  return Status::Ok();
}

Status CcTeamFilter::meetMap(CcVehicle& v, FrameReport* fr) {
  Impl& m = *impl_;
  // The met landmarks enter as one iterated update (CovarianceHelper::iteratedUpdate), first
  // linearised at this UAV moved by the translation that puts where it sees them onto where the
  // map has them (median per axis; no yaw: initial headings are known, §6.3.1). Linearised
  // metres away from the truth the update would invent information (the UAV's yaw collapses,
  // measured on coop_pair); starting from the prior, the shift comes through the gain and the
  // covariance pays for it. Gated per observation, so a wrong association cannot drag the UAV.
  SlamState start = m.state;
  const StateVariable* veh = start.find(v.key);
  vehicle_model::moveRigidly(start, *veh, start.value(*veh).head<3>() + m.meetShift(v), 0.0);
  const Eigen::VectorXd mean_before = m.state.mean();
  const CovarianceHelper::Linearisation linearise = [&](const SlamState& at, MeasurementBatch* b) {
    return v.updater.linearise(at, v.book, m.frame, StereoUpdater::Selection::kOnlyListed, m.meet,
                               StereoUpdater::Jacobians::kPlain, 1.0, b);
  };
  IteratedUpdateOptions iterated;
  iterated.max_iterations = o_.slam.slam.loop_closure_passes;
  UpdateReport u;
  if (Status s = CovarianceHelper::iteratedUpdate(m.state, std::move(start), linearise, iterated,
                                                  m.policy, &m.meet_batch, &u);
      !s.ok()) {
    return s;
  }
  stats_.filter.add(u);
  fr->theta_reduced = fr->theta_reduced || u.theta_reduced;
  if (u.rows == 0) return Status::Ok();
  m.followCorrectionEverywhere(mean_before);
  ++stats_.agents[v.agent_id].rendezvous;
  return Status::Ok();
}

Status CcTeamFilter::runRecipe(CcVehicle& v, const CcObservationBatch& batch, CcStepReport* r) {
  Impl& m = *impl_;
  FrameReport& fr = r->frame;
  fr.t_us = batch.t_us;
  fr.observations = static_cast<int>(batch.frame.observations.size());
  const int64_t t_us = batch.t_us;
  // 2. Joint ids and types (§6.3.1); type-2 landmarks of the state enter this UAV's book.
  m.associate(v, batch, o_);
  for (int type : m.types) {
    r->type1 += type == 1 ? 1 : 0;
    r->type2 += type == 2 ? 1 : 0;
    r->type3 += type == 3 ? 1 : 0;
  }
  // 3. This UAV's k nearest over the joint map: archive, re-activate.
  if (Status st = m.manageMap(v, t_us, o_.slam.slam, o_.reactivation_inflation, &fr); !st.ok())
    return st;
  // 4. Loop closing, then the gated updates of the other observations.
  LoopReport loop;
  if (Status s = v.loop_closer.process(m.state, v.book, m.frame, t_us, v.updater, m.policy,
                                       &stats_.filter, &loop);
      !s.ok()) {
    return s;
  }
  fr.loop_landmarks = loop.loop_landmarks;
  fr.loop_closure = loop.loop_closure;
  fr.loop_refused = loop.loop_refused;
  // The loop moved every UAV correlated with this one: their books follow.
  if (loop.loop_closure) m.followCorrectionEverywhere(loop.mean_before);
  fr.theta_reduced = loop.theta_reduced;
  // A rendezvous first (cc_team_filter.h), also through landmarks step 3 brought back, then
  // the gated updates of the rest.
  std::vector<int64_t> done = v.loop_closer.loopIds();
  m.meetReentered(v, done, t_us, o_);
  if (!m.meet.empty()) {
    if (Status st = meetMap(v, &fr); !st.ok()) return st;
    std::vector<int64_t> both;
    std::set_union(done.begin(), done.end(), m.meet.begin(), m.meet.end(),
                   std::back_inserter(both));
    done.swap(both);
  }
  std::vector<UpdateReport> passes;
  const Status s =
      v.updater.update(m.state, v.book, m.frame, o_.slam.slam.observation_passes,
                       StereoUpdater::Selection::kAllButListed, done, m.policy, &passes);
  for (const UpdateReport& u : passes) {
    if (u.observations_accepted + u.observations_rejected > 0) stats_.filter.add(u);
    fr.updated = u.observations_accepted;
    fr.rejected = u.observations_rejected;
    fr.theta_reduced = fr.theta_reduced || u.theta_reduced;
  }
  if (!s.ok()) return s;
  // 5. Initialise the landmarks new to the joint map; they join this UAV's active set.
  const std::size_t before = m.state.variables().size();
  if (Status st = v.initialiser.initialise(m.state, v.book, m.archive, m.frame, t_us,
                                           &m.next_fresh_id, &fr.initialised);
      !st.ok()) {
    return st;
  }
  m.afterInitialisation(v, before);
  fr.state_size = m.state.size();
  fr.landmarks_in_state = m.state.landmarkCount();
  return Status::Ok();
}

}  // namespace cvslam::coop
