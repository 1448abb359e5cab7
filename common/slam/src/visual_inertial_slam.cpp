#include "cvslam/slam/visual_inertial_slam.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cvslam/filter/vehicle_model.h"
#include "cvslam/io/config_node.h"
#include "cvslam/slam/landmark_lifecycle.h"

namespace cvslam {

Status VisualInertialSlamOptions::load(const ConfigNode& root) {
  filter.load(root.child("filter"));
  ins.load(root.child("ins"));
  map.load(root.child("map"));
  slam.load(root.child("slam"));
  gps.load(root.child("gps"));
  return root.status();
}

VisualInertialSlam::VisualInertialSlam(const VisualInertialSlamOptions& options,
                                       const StereoCamera& camera)
    : o_(options),
      camera_(camera),
      propagator_(options.ins),
      noise_monitor_(options.ins.noise_monitor),
      map_manager_(options.map),
      updater_(vehicle_, camera, options.slam),
      initialiser_(vehicle_, camera, options.slam),
      loop_closer_(vehicle_, camera, options.slam),
      reactivation_(options.slam.intersection),
      ci_updater_(vehicle_),
      gps_updater_(vehicle_, options.gps) {
  Expected<UpdatePolicy> policy = o_.filter.policy();
  if (policy.ok()) {
    policy_ = *policy;
    policy_status_ = o_.slam.checkChart();
  } else {
    policy_status_ = policy.status();
  }
}

void VisualInertialSlam::configureModels() {
  updater_ = StereoUpdater(vehicle_, camera_, o_.slam);
  initialiser_ = LandmarkInitialiser(vehicle_, camera_, o_.slam);
  loop_closer_ = LoopCloser(vehicle_, camera_, o_.slam);
  updater_.setOracle(oracle_);
  initialiser_.setOracle(oracle_);
  propagation_.setOracle(oracle_);
  if (policy_status_.ok()) policy_status_ = o_.slam.checkChart();  // a setter may break it
  // A Jacobian at the truth is defined only in coordinates that do not depend on the estimate:
  // the error state's δθ lives about the estimate's nominal R̂, so ∂h/∂δθ at the true R mixes
  // two charts, and the tilt between them lets updates inform the global yaw (the yaw σ fell
  // from 1° to 0.6° in the first second on team3_aerial; docs/results/ideal_ekf.md).
  if (policy_status_.ok() && oracle_ != nullptr &&
      o_.ins.attitude == vehicle::Attitude::kErrorState)
    policy_status_ = Status::Error(
        "the ideal EKF (Jacobians at the truth) needs ins.attitude: euler, whose coordinates do "
        "not depend on the estimate");
}

void VisualInertialSlam::setLinearisationOracle(const LinearisationOracle* oracle) {
  oracle_ = oracle;
  state_.setErrorChart(chart());
  configureModels();
}

ErrorChart VisualInertialSlam::chart() const {
  // The ideal EKF's Jacobians are at the truth, which an update does not move: its chart is
  // the additive one whatever the configuration (docs/results/ideal_ekf.md).
  return oracle_ != nullptr ? ErrorChart::kAdditive : o_.slam.error_chart;
}

void VisualInertialSlam::setMeasurementModel(const SlamOptions& slam) {
  SlamOptions& o = o_.slam;
  if (o.first_estimate_jacobians == slam.first_estimate_jacobians &&
      o.observability_constrained == slam.observability_constrained &&
      o.second_order_noise == slam.second_order_noise &&
      o.second_order_mean == slam.second_order_mean && o.pixel_sigma == slam.pixel_sigma)
    return;
  o.first_estimate_jacobians = slam.first_estimate_jacobians;
  o.observability_constrained = slam.observability_constrained;
  o.second_order_noise = slam.second_order_noise;
  o.second_order_mean = slam.second_order_mean;
  o.pixel_sigma = slam.pixel_sigma;
  configureModels();
}

Status VisualInertialSlam::initialize(int64_t t_us, const Eigen::VectorXd& x_v,
                                      const Eigen::MatrixXd& P_v) {
  return initializeVehicle(t_us, x_v, nullptr, P_v);
}

Status VisualInertialSlam::initialize(int64_t t_us, const Eigen::VectorXd& x_v,
                                      const Eigen::Quaterniond& q_BtoN,
                                      const Eigen::MatrixXd& P_v) {
  if (o_.ins.attitude != vehicle::Attitude::kErrorState) {
    return Status::Error("initial rotation given, but ins.attitude is not error_state");
  }
  return initializeVehicle(t_us, x_v, &q_BtoN, P_v);
}

Status VisualInertialSlam::initializeVehicle(int64_t t_us, const Eigen::VectorXd& x_v,
                                             const Eigen::Quaterniond* q_BtoN,
                                             const Eigen::MatrixXd& P_v) {
  if (!policy_status_.ok()) return policy_status_;
  const int n = propagator_.stateSize();
  if (x_v.size() != n || P_v.rows() != n || P_v.cols() != n) {
    return Status::Error("initial vehicle state must have " + std::to_string(n) + " entries");
  }
  if (!x_v.allFinite() || !P_v.allFinite()) {
    return Status::Error("initial vehicle state is not finite");
  }
  state_ = SlamState();
  state_.setErrorChart(chart());
  archive_ = LandmarkArchive();
  book_.clear();
  const Status added = q_BtoN != nullptr
                           ? vehicle_model::addVehicle(state_, vehicle_, x_v, *q_BtoN, P_v)
                           : vehicle_model::addVehicle(state_, vehicle_, x_v, P_v, o_.ins.attitude);
  if (!added.ok()) return added;
  t_us_ = t_us;
  propagation_.reset(t_us);
  book_.setVehicleYawDirection(
      vehicle_model::yawDirection(vehicle_model::pose(state_, *state_.find(vehicle_)), n));
  initialized_ = true;
  return Status::Ok();
}

Status VisualInertialSlam::addImu(const ImuSample& sample) {
  if (!initialized_) return Status::Error("addImu before initialize");
  if (Status s = propagation_.addImu(sample); !s.ok()) return s;
  noise_monitor_.add(sample);
  return Status::Ok();
}

Status VisualInertialSlam::propagateTo(int64_t t_us) {
  if (!initialized_) return Status::Error("propagateTo before initialize");
  if (noise_monitor_.ready()) {
    propagator_.setMeasuredNoiseDensities(noise_monitor_.gyroDensity(),
                                          noise_monitor_.accelDensity());
  }
  if (Status s = propagation_.propagateTo(t_us, propagator_, policy_, vehicle_, state_, book_);
      !s.ok()) {
    return s;
  }
  t_us_ = propagation_.time();
  return Status::Ok();
}

Status VisualInertialSlam::addGps(const GpsFix& fix, UpdateReport* report) {
  if (!o_.gps.enabled) return Status::Ok();
  if (!initialized_) return Status::Error("gps fix before initialize");
  if (fix.t_us < t_us_) {
    return Status::Error("gps fix at " + std::to_string(fix.t_us) +
                         " µs is older than the filter (" + std::to_string(t_us_) + " µs)");
  }
  if (Status s = propagateTo(fix.t_us); !s.ok()) return s;
  UpdateReport local;
  if (Status s = gps_updater_.update(state_, fix, policy_, &local); !s.ok()) return s;
  stats_.add(local);
  if (report != nullptr) *report = local;
  return Status::Ok();
}

const std::vector<uint8_t>* VisualInertialSlam::descriptorOf(int64_t landmark_id) const {
  if (const LandmarkBookEntry* r = book_.find(landmark_id)) return &r->descriptor;
  if (const ArchivedLandmark* a = archive_.find(landmark_id)) return &a->descriptor;
  return nullptr;
}

Status VisualInertialSlam::manageMap(const StereoFrameObservations& frame, FrameReport* report) {
  const Eigen::Vector3d m_star = frameVirtualPoint(map_manager_, camera_, state_, vehicle_, frame);

  const std::vector<int64_t> observed = observedLandmarkIds(frame);
  std::vector<MapCandidate> candidates;
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(v.key.id);
    const LandmarkBookEntry* e = book_.find(id);
    candidates.push_back({id, state_.value(v),
                          std::binary_search(observed.begin(), observed.end(), id), false,
                          e != nullptr ? e->last_seen_us : 0});
  }
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    const ArchivedLandmark* a = archive_.find(id);
    if (a != nullptr && mayReenter(state_, id, *a, t_us_, o_.slam)) {
      candidates.push_back({id, a->p_LinN, true, true});
    }
  }
  const std::vector<int64_t> keep = map_manager_.select(candidates, m_star);
  std::vector<Eigen::Vector3d> keep_near;
  if (o_.slam.held_eviction == SlamOptions::HeldEviction::kNearest) keep_near.push_back(m_star);

  // Archive the state landmarks that lost their place (marginalisation is exact: the
  // archive keeps the mean and the marginal covariance, §5.8).
  for (const MapCandidate& cand : candidates) {
    if (std::binary_search(keep.begin(), keep.end(), cand.landmark_id)) continue;
    // An archived candidate that stays archived is not in the state.
    if (!state_.has(VariableKey::landmark(static_cast<uint64_t>(cand.landmark_id)))) continue;
    archiveLandmark(state_, archive_, cand.landmark_id, book_.remove(cand.landmark_id), t_us_,
                    o_.slam.held_landmarks, keep_near, o_.slam.anchor_landmarks);
    ++report->archived;
  }
  // Re-activate the chosen archived landmarks (loop closing, §5.5.2), each as the options
  // say (SlamOptions::Reentry).
  std::vector<int64_t> intersected;
  for (int64_t id : keep) {
    if (state_.has(VariableKey::landmark(static_cast<uint64_t>(id)))) continue;
    const ArchivedLandmark* a = archive_.find(id);
    if (a == nullptr) continue;
    if (isHeld(state_, id)) {  // exact: its correlations never left the state
      if (reactivateLandmark(state_, book_, archive_, id)) ++report->reactivated;
      continue;
    }
    switch (reentryOf(*a, t_us_, o_.slam)) {
      case SlamOptions::Reentry::kRemap:
        archive_.take(id);  // the initialiser (step 5) maps it anew
        break;
      case SlamOptions::Reentry::kIntersection:
        intersected.push_back(id);
        break;
      case SlamOptions::Reentry::kIndependent:
        if (reactivateLandmark(state_, book_, archive_, id)) ++report->reactivated;
        break;
    }
  }
  if (intersected.empty()) return Status::Ok();
  ReactivationReport r;
  Status s = reactivation_.reactivate(state_, book_, archive_, intersected, updater_, frame, &r);
  report->reactivated += r.landmarks;
  return s;
}

Status VisualInertialSlam::updateObserved(const StereoFrameObservations& frame,
                                          FrameReport* report) {
  std::vector<UpdateReport> passes;
  const Status s = updater_.update(state_, book_, frame, o_.slam.observation_passes,
                                   StereoUpdater::Selection::kAllButListed, loop_closer_.loopIds(),
                                   policy_, &passes);
  for (const UpdateReport& u : passes) {
    if (u.observations_accepted + u.observations_rejected > 0) stats_.add(u);
    report->updated = u.observations_accepted;
    report->rejected = u.observations_rejected;
    report->nis = u.nis;
    report->nis_dof = u.rows;
    report->theta_reduced = report->theta_reduced || u.theta_reduced;
  }
  return s;
}

Status VisualInertialSlam::processFrame(const StereoFrameObservations& frame, FrameReport* report) {
  if (!initialized_) return Status::Error("processFrame before initialize");
  if (!policy_status_.ok()) return policy_status_;
  FrameReport local;
  FrameReport& r = report != nullptr ? *report : local;
  r = FrameReport();
  r.t_us = frame.t_us;
  r.observations = static_cast<int>(frame.observations.size());
  for (const StereoObservation& obs : frame.observations) {
    if (!obs.z.allFinite()) return Status::Error("observation with non-finite pixels");
  }
  auto t0 = std::chrono::steady_clock::now();
  // Milliseconds since t0, and t0 moved to now.
  auto lap = [&t0] {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t0).count();
    t0 = now;
    return ms;
  };
  // 1. Propagate the vehicle to the frame time.
  if (Status s = propagateTo(frame.t_us); !s.ok()) return s;
  r.predict_ms = lap();
  // 2., 3. The virtual point m* and the k nearest landmarks: archive, re-activate.
  if (Status s = manageMap(frame, &r); !s.ok()) return s;
  r.map_ms = lap();
  // 4. Close a loop when enough loop landmarks agree, then the gated updates of the others.
  LoopReport loop;
  if (Status s =
          loop_closer_.process(state_, book_, frame, t_us_, updater_, policy_, &stats_, &loop);
      !s.ok()) {
    return s;
  }
  r.loop_landmarks = loop.loop_landmarks;
  r.loop_closure = loop.loop_closure;
  r.loop_refused = loop.loop_refused;
  r.theta_reduced = loop.theta_reduced;
  if (Status s = updateObserved(frame, &r); !s.ok()) return s;
  r.update_ms = lap();
  // 5. Initialise the never-seen landmarks.
  if (Status s = initialiser_.initialise(state_, book_, archive_, frame, t_us_, &next_fresh_id_,
                                         &r.initialised);
      !s.ok()) {
    return s;
  }
  r.initialise_ms = lap();
  r.state_size = state_.size();
  r.landmarks_in_state = state_.landmarkCount();
  return Status::Ok();
}

Eigen::VectorXd VisualInertialSlam::vehicleState() const {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
  vehicle_model::eulerLayout(state_, *state_.find(vehicle_), &x, &P);
  return x;
}

Eigen::MatrixXd VisualInertialSlam::vehicleCovariance() const {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
  vehicle_model::eulerLayout(state_, *state_.find(vehicle_), &x, &P);
  return P;
}

vehicle_model::Pose VisualInertialSlam::vehiclePose() const {
  return vehicle_model::pose(state_, *state_.find(vehicle_));
}

std::vector<MapLandmark> VisualInertialSlam::map() const {
  std::vector<MapLandmark> out;
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    MapLandmark m;
    m.id = static_cast<int64_t>(v.key.id);
    if (const LandmarkBookEntry* r = book_.find(m.id)) m.index = r->index;
    m.p_LinN = state_.value(v);
    m.covariance = state_.covarianceOf(v);
    m.in_state = true;
    out.push_back(m);
  }
  for (const auto& [id, a] : archive_.all()) {
    out.push_back({id, a.index, a.p_LinN, a.covariance, false});
  }
  std::sort(out.begin(), out.end(),
            [](const MapLandmark& a, const MapLandmark& b) { return a.id < b.id; });
  return out;
}

}  // namespace cvslam
