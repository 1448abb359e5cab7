#include "cvslam/slam/visual_inertial_slam.h"

#include <algorithm>
#include <cmath>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"
#include "cvslam/slam/loop_alignment.h"

namespace cvslam {

Status SlamOptions::load(const ConfigNode& node) {
  node.get("pixel_sigma", pixel_sigma);
  node.get("observation_passes", observation_passes);
  node.get("scale_noise_per_pass", scale_noise_per_pass);
  node.get("max_new_landmarks_per_frame", max_new_landmarks_per_frame);
  node.get("min_init_disparity_px", min_init_disparity_px);
  node.get("loop_closure_min_age_s", loop_closure_min_age_s);
  node.get("reactivation_min_age_s", reactivation_min_age_s);
  node.check(reactivation_min_age_s >= 0.0, "reactivation_min_age_s", "must be ≥ 0");
  node.get("first_estimate_jacobians", first_estimate_jacobians);
  node.get("observability_constrained", observability_constrained);
  node.get("loop_closure_min_landmarks", loop_closure_min_landmarks);
  node.get("loop_closure_max_residual_m", loop_closure_max_residual_m);
  node.get("loop_closure_passes", loop_closure_passes);
  node.get("loop_closure_window_s", loop_closure_window_s);
  node.check(loop_closure_window_s > 0.0, "loop_closure_window_s", "must be > 0");
  node.check(loop_closure_min_landmarks >= 0, "loop_closure_min_landmarks", "must be ≥ 0");
  node.check(loop_closure_max_residual_m > 0.0, "loop_closure_max_residual_m", "must be > 0");
  node.check(loop_closure_passes >= 1, "loop_closure_passes", "must be ≥ 1");
  node.get("initial_accel_bias_sigma", initial_accel_bias_sigma);
  node.get("initial_gyro_bias_sigma", initial_gyro_bias_sigma);
  node.get("initial_accel_bias", initial_accel_bias);
  node.get("initial_gyro_bias", initial_gyro_bias);
  node.check(initial_accel_bias.allFinite() && initial_gyro_bias.allFinite(), "initial_accel_bias",
             "initial biases must be finite");
  node.check(initial_accel_bias_sigma > 0.0 && initial_gyro_bias_sigma > 0.0,
             "initial_accel_bias_sigma", "initial bias sigmas must be > 0");
  node.check(pixel_sigma > 0.0, "pixel_sigma", "must be > 0");
  node.check(observation_passes >= 1, "observation_passes", "must be ≥ 1");
  node.check(max_new_landmarks_per_frame >= 0, "max_new_landmarks_per_frame", "must be ≥ 0");
  node.check(min_init_disparity_px > 0.0, "min_init_disparity_px", "must be > 0");
  node.check(loop_closure_min_age_s >= 0.0, "loop_closure_min_age_s", "must be ≥ 0");
  return node.status();
}

Status VisualInertialSlamOptions::load(const ConfigNode& root) {
  filter.load(root.child("filter"));
  ins.load(root.child("ins"));
  map.load(root.child("map"));
  slam.load(root.child("slam"));
  return root.status();
}

VisualInertialSlam::VisualInertialSlam(const VisualInertialSlamOptions& options,
                                       const StereoCamera& camera)
    : o_(options), camera_(camera), propagator_(options.ins), map_manager_(options.map) {
  Expected<UpdatePolicy> policy = o_.filter.policy();
  if (policy.ok()) {
    policy_ = *policy;
  } else {
    policy_status_ = policy.status();
  }
}

Status VisualInertialSlam::initialize(int64_t t_us, const Eigen::VectorXd& x_v,
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
  archive_ = LandmarkArchive();
  info_.clear();
  pending_loop_.clear();
  if (Status s = CovarianceHelper::addVariable(state_, vehicle_, x_v, P_v); !s.ok()) return s;
  t_us_ = t_us;
  imu_buffer_.clear();
  yaw_direction_ = vehicleYawDirection(x_v.head<3>(), n);
  initialized_ = true;
  return Status::Ok();
}

Status VisualInertialSlam::addImu(const ImuSample& sample) {
  if (!initialized_) return Status::Error("addImu before initialize");
  if (!sample.gyro_B.allFinite() || !sample.accel_B.allFinite()) {
    return Status::Error("IMU sample at t=" + std::to_string(sample.t_us) + " µs is not finite");
  }
  const int64_t last = imu_buffer_.empty() ? t_us_ - 1 : imu_buffer_.back().t_us;
  if (sample.t_us <= last) {
    return Status::Error("IMU sample at t=" + std::to_string(sample.t_us) +
                         " µs is not after the previous one");
  }
  if (imu_buffer_.empty() && sample.t_us > t_us_) {
    // The state time has no sample: hold this one back to it (zero-order hold).
    ImuSample at_state = sample;
    at_state.t_us = t_us_;
    imu_buffer_.push_back(at_state);
  }
  imu_buffer_.push_back(sample);
  return Status::Ok();
}

Status VisualInertialSlam::propagateTo(int64_t t_us) {
  if (!initialized_) return Status::Error("propagateTo before initialize");
  if (t_us < t_us_) return Status::Error("frame time goes backwards");
  if (imu_buffer_.empty() || t_us == t_us_) return Status::Ok();
  // Samples after the frame stay buffered; the frame time gets an interpolated sample.
  std::vector<ImuSample> segment;
  std::vector<ImuSample> rest;
  for (const ImuSample& s : imu_buffer_) (s.t_us <= t_us ? segment : rest).push_back(s);
  if (segment.back().t_us < t_us) {
    ImuSample end = segment.back();
    if (!rest.empty()) {
      const ImuSample& next = rest.front();
      const double a =
          static_cast<double>(t_us - end.t_us) / static_cast<double>(next.t_us - end.t_us);
      end.gyro_B += a * (next.gyro_B - end.gyro_B);
      end.accel_B += a * (next.accel_B - end.accel_B);
    }
    end.t_us = t_us;
    segment.push_back(end);
  }
  if (segment.size() >= 2) {
    InsTransition tr;
    if (Status s = propagator_.propagate(state_.value(*state_.find(vehicle_)), segment, &tr);
        !s.ok()) {
      return s;
    }
    if (Status s = CovarianceHelper::propagate(state_, vehicle_, tr.x, tr.Phi, tr.Qd, policy_);
        !s.ok()) {
      return s;
    }
    yaw_direction_ = tr.Phi * yaw_direction_;  // Φ u_v: the transition's own image of u_v
  }
  imu_buffer_.clear();
  imu_buffer_.push_back(segment.back());
  imu_buffer_.insert(imu_buffer_.end(), rest.begin(), rest.end());
  t_us_ = t_us;
  return Status::Ok();
}

const std::vector<uint8_t>* VisualInertialSlam::descriptorOf(int64_t landmark_id) const {
  if (auto it = info_.find(landmark_id); it != info_.end()) return &it->second.descriptor;
  if (const ArchivedLandmark* a = archive_.find(landmark_id)) return &a->descriptor;
  return nullptr;
}

Eigen::Matrix<double, 9, 1> VisualInertialSlam::pose9() const {
  return state_.value(*state_.find(vehicle_)).head<9>();
}

void VisualInertialSlam::manageMap(const StereoFrameObservations& frame, FrameReport* report) {
  const Eigen::Matrix<double, 9, 1> x = pose9();
  const StereoCameraOptions& c = camera_.options();
  std::vector<double> depths;
  depths.reserve(frame.observations.size());
  for (const StereoObservation& obs : frame.observations) {
    const double disparity = obs.z(0) - obs.z(2);
    if (disparity > 0.0) depths.push_back(c.fx * c.baseline / disparity);
  }
  const Eigen::Vector3d m_star = KNearestMapManager::virtualPoint(
      camera_, x.segment<3>(vehicle::kPosition), x.segment<3>(vehicle::kAttitude),
      map_manager_.sceneDepth(depths));

  std::vector<int64_t> observed;
  observed.reserve(frame.observations.size());
  for (const StereoObservation& obs : frame.observations) {
    if (obs.landmark_id >= 0) observed.push_back(obs.landmark_id);
  }
  std::sort(observed.begin(), observed.end());
  std::vector<MapCandidate> candidates;
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(v.key.id);
    candidates.push_back(
        {id, state_.value(v), std::binary_search(observed.begin(), observed.end(), id)});
  }
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    const ArchivedLandmark* a = archive_.find(id);
    if (a != nullptr &&
        static_cast<double>(t_us_ - a->archived_us) * 1e-6 >= o_.slam.reactivation_min_age_s) {
      candidates.push_back({id, a->p_LinN, true, true});
    }
  }
  const std::vector<int64_t> keep = map_manager_.select(candidates, m_star);

  // Archive the state landmarks that lost their place (marginalisation is exact: the
  // archive keeps the mean and the marginal covariance, §5.8).
  for (const MapCandidate& cand : candidates) {
    if (std::binary_search(keep.begin(), keep.end(), cand.landmark_id)) continue;
    const VariableKey key = VariableKey::landmark(static_cast<uint64_t>(cand.landmark_id));
    const StateVariable* v = state_.find(key);
    if (v == nullptr) continue;  // an archived candidate that stays archived
    ArchivedLandmark a;
    a.p_LinN = state_.value(*v);
    a.covariance = state_.covarianceOf(*v);
    auto it = info_.find(cand.landmark_id);
    if (it != info_.end()) {
      a.index = it->second.index;
      a.first_seen_us = it->second.first_seen_us;
      a.last_seen_us = it->second.last_seen_us;
      a.descriptor = std::move(it->second.descriptor);
      a.yaw_direction = it->second.yaw_direction;
      info_.erase(it);
    }
    a.archived_us = t_us_;
    pending_loop_.erase(cand.landmark_id);
    archive_.store(cand.landmark_id, std::move(a));
    CovarianceHelper::marginalize(state_, key);
    ++report->archived;
  }
  // Re-activate the chosen archived landmarks (loop closing, §5.5.2).
  for (int64_t id : keep) {
    const VariableKey key = VariableKey::landmark(static_cast<uint64_t>(id));
    if (state_.has(key)) continue;
    std::optional<ArchivedLandmark> a = archive_.take(id);
    if (!a) continue;
    CovarianceHelper::addVariable(state_, key, a->p_LinN, a->covariance);
    ++report->reactivated;
    info_[id] = {a->index,
                 a->first_seen_us,
                 a->last_seen_us,
                 std::move(a->descriptor),
                 a->p_LinN,
                 a->yaw_direction,
                 false};
  }
}

int VisualInertialSlam::alignLoop(const StereoFrameObservations& frame) {
  const StateVariable* veh = state_.find(vehicle_);
  const Eigen::Matrix<double, 9, 1> x = state_.value(*veh).head<9>();
  std::vector<int64_t> ids;
  std::vector<LoopPair> pairs;
  for (const StereoObservation& obs : frame.observations) {
    if (!std::binary_search(loop_ids_.begin(), loop_ids_.end(), obs.landmark_id)) continue;
    const StateVariable* lm =
        state_.find(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id)));
    Eigen::Vector3d p_observed;
    if (lm == nullptr || !camera_.triangulate(obs.z, x, &p_observed).ok()) continue;
    ids.push_back(obs.landmark_id);
    pairs.push_back({p_observed, state_.value(*lm)});
  }
  // Fit, drop pairs that disagree with the fit (wrong associations), fit again.
  const Eigen::Vector3d pivot = x.head<3>();
  Expected<LoopAlignment> fit = cvslam::alignLoop(pairs, pivot);
  for (int round = 0; round < 2 && fit.ok(); ++round) {
    std::vector<int64_t> kept_ids;
    std::vector<LoopPair> kept;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if ((fit->apply(pairs[i].p_observed_N) - pairs[i].p_map_N).norm() <=
          o_.slam.loop_closure_max_residual_m) {
        kept_ids.push_back(ids[i]);
        kept.push_back(pairs[i]);
      }
    }
    ids.swap(kept_ids);
    pairs.swap(kept);
    fit = cvslam::alignLoop(pairs, pivot);
  }
  loop_ids_.clear();
  if (!fit.ok() || static_cast<int>(ids.size()) < o_.slam.loop_closure_min_landmarks) return 0;
  loop_ids_ = ids;
  std::sort(loop_ids_.begin(), loop_ids_.end());

  // Move the linearisation point: the vehicle and the landmarks that drifted with it (all
  // state landmarks but the loop ones) by the fitted rigid motion. The update that follows
  // then sees small innovations and corrects the covariance as usual.
  Eigen::VectorXd xv = state_.value(*veh);
  xv.head<3>() = fit->apply(xv.head<3>());
  xv(vehicle::kAttitude + 2) = wrapAngle(xv(vehicle::kAttitude + 2) + fit->yaw);
  state_.setValue(*veh, xv);
  // The alignment moves the estimate along the unobservable directions; their tracked
  // directions move with it.
  yaw_direction_.head<3>() = moveYawDirection(yaw_direction_.head<3>(), *fit);
  const auto min_age_us = static_cast<int64_t>(o_.slam.loop_closure_min_age_s * 1e6);
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    const auto id = static_cast<int64_t>(v.key.id);
    if (std::binary_search(loop_ids_.begin(), loop_ids_.end(), id)) continue;
    // Only landmarks seen recently drifted with the vehicle; old ones (the full map keeps
    // them in the state) are in the old frame, like the loop landmarks.
    auto info = info_.find(id);
    if (info == info_.end() || t_us_ - info->second.last_seen_us >= min_age_us) continue;
    state_.setValue(v, fit->apply(state_.value(v)));
    info->second.first_estimate = fit->apply(info->second.first_estimate);
    info->second.yaw_direction = moveYawDirection(info->second.yaw_direction, *fit);
  }
  return static_cast<int>(loop_ids_.size());
}

Status VisualInertialSlam::updatePass(const StereoFrameObservations& frame, int passes,
                                      Selection selection, const UpdatePolicy& policy,
                                      UpdateReport* report) {
  const StateVariable* veh = state_.find(vehicle_);
  const Eigen::Matrix<double, 9, 1> x = state_.value(*veh).head<9>();
  const double noise_scale = o_.slam.scale_noise_per_pass ? passes : 1.0;
  const Eigen::Matrix4d R =
      Eigen::Matrix4d::Identity() * (o_.slam.pixel_sigma * o_.slam.pixel_sigma * noise_scale);
  batch_.reset(state_.size(), 4 * static_cast<int>(frame.observations.size()));
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  for (const StereoObservation& obs : frame.observations) {
    const int64_t id = obs.landmark_id;
    if (id < 0) continue;
    if (selection != Selection::kAll) {
      const bool loop = std::binary_search(loop_ids_.begin(), loop_ids_.end(), id);
      if (loop != (selection == Selection::kOnlyLoop)) continue;
    }
    const StateVariable* lm = state_.find(VariableKey::landmark(static_cast<uint64_t>(id)));
    if (lm == nullptr) continue;
    const Eigen::Vector3d p_LinN = state_.value(*lm);
    // Predicted landmark behind the camera: the linearisation is meaningless, skip it.
    if (camera_.landmarkInCamera(x.head<3>(), x.segment<3>(vehicle::kAttitude), p_LinN).z() <=
        0.0) {
      continue;
    }
    Eigen::Vector4d z_hat;
    auto info = info_.find(id);
    if (o_.slam.first_estimate_jacobians && info != info_.end()) {
      z_hat = camera_.project(x, p_LinN);
      camera_.project(x, info->second.first_estimate, &dz_dxv, &dz_dpL);
    } else {
      z_hat = camera_.project(x, p_LinN, &dz_dxv, &dz_dpL);
    }
    if (o_.slam.observability_constrained && info != info_.end() && info->second.constrained) {
      constrainStereoJacobian(yaw_direction_, info->second.yaw_direction, &dz_dxv, &dz_dpL);
    }
    const int g = batch_.addObservation(obs.z - z_hat, R);
    if (g < 0) break;
    batch_.setJacobian(g, veh->index, dz_dxv);
    batch_.setJacobian(g, *lm, dz_dpL);
  }
  if (batch_.groups() == 0) return Status::Ok();
  return CovarianceHelper::update(state_, batch_, policy, report);
}

Status VisualInertialSlam::initialiseNew(const StereoFrameObservations& frame,
                                         FrameReport* report) {
  if (o_.slam.max_new_landmarks_per_frame == 0) return Status::Ok();
  const StateVariable* veh = state_.find(vehicle_);
  const Eigen::Matrix<double, 9, 1> x = state_.value(*veh).head<9>();
  struct NewLandmark {
    double range2;
    std::size_t obs;
    Eigen::Vector3d p_LinN;
  };
  std::vector<NewLandmark> fresh;
  for (std::size_t i = 0; i < frame.observations.size(); ++i) {
    const StereoObservation& obs = frame.observations[i];
    const int64_t id = obs.landmark_id;
    if (id >= 0 &&
        (state_.has(VariableKey::landmark(static_cast<uint64_t>(id))) || archive_.contains(id))) {
      continue;  // known: updated above, or archived and not chosen this frame
    }
    if (obs.z(0) - obs.z(2) < o_.slam.min_init_disparity_px) continue;
    Eigen::Vector3d p_LinN;
    if (!camera_.triangulate(obs.z, x, &p_LinN).ok()) continue;
    fresh.push_back({(p_LinN - x.head<3>()).squaredNorm(), i, p_LinN});
  }
  // The nearest points are the best triangulated ones (disparity grows as 1/depth).
  const std::size_t n_new =
      std::min(fresh.size(), static_cast<std::size_t>(o_.slam.max_new_landmarks_per_frame));
  std::partial_sort(fresh.begin(), fresh.begin() + static_cast<std::ptrdiff_t>(n_new), fresh.end(),
                    [](const NewLandmark& a, const NewLandmark& b) {
                      return a.range2 < b.range2 || (a.range2 == b.range2 && a.obs < b.obs);
                    });
  const Eigen::Matrix4d R = Eigen::Matrix4d::Identity() * o_.slam.pixel_sigma * o_.slam.pixel_sigma;
  StereoCamera::Matrix3x9d dpL_dxv;
  StereoCamera::Matrix3x4d dpL_dz;
  const int vehicle_size = veh->size;
  Eigen::MatrixXd dpL_dvehicle = Eigen::MatrixXd::Zero(3, vehicle_size);
  for (std::size_t k = 0; k < n_new; ++k) {
    const StereoObservation& obs = frame.observations[fresh[k].obs];
    Eigen::Vector3d p_LinN;
    if (!camera_.triangulate(obs.z, x, &p_LinN, &dpL_dxv, &dpL_dz).ok()) continue;
    const int64_t id = obs.landmark_id >= 0 ? obs.landmark_id : next_fresh_id_++;
    dpL_dvehicle.leftCols<9>() = dpL_dxv;  // bias states do not enter the triangulation
    if (Status s =
            CovarianceHelper::augment(state_, VariableKey::landmark(static_cast<uint64_t>(id)),
                                      p_LinN, vehicle_, dpL_dvehicle, dpL_dz, R);
        !s.ok()) {
      return s;
    }
    // u_L = ∂p_L/∂x_v u_v: the landmark inherits the vehicle's tracked yaw direction.
    const Eigen::Vector3d u_L = dpL_dvehicle * yaw_direction_;
    info_[id] = {obs.index, t_us_, t_us_, obs.descriptor, p_LinN, u_L, true};
    ++report->initialised;
  }
  return Status::Ok();
}

Status VisualInertialSlam::processFrame(const StereoFrameObservations& frame, FrameReport* report) {
  if (!initialized_) return Status::Error("processFrame before initialize");
  FrameReport local;
  FrameReport& r = report != nullptr ? *report : local;
  r = FrameReport();
  r.t_us = frame.t_us;
  r.observations = static_cast<int>(frame.observations.size());
  for (const StereoObservation& obs : frame.observations) {
    if (!obs.z.allFinite()) return Status::Error("observation with non-finite pixels");
  }
  if (Status s = propagateTo(frame.t_us); !s.ok()) return s;

  manageMap(frame, &r);
  // Loop landmarks (§5.5.2): seen again after a long absence. Until enough of them agree
  // they stay out of the gated updates, where a drifted vehicle would reject them one by one.
  const auto min_age_us = static_cast<int64_t>(o_.slam.loop_closure_min_age_s * 1e6);
  const auto window_us = static_cast<int64_t>(o_.slam.loop_closure_window_s * 1e6);
  for (auto it = pending_loop_.begin(); it != pending_loop_.end();) {
    it = t_us_ - it->second > window_us ? pending_loop_.erase(it) : std::next(it);
  }
  loop_ids_.clear();
  for (const StereoObservation& obs : frame.observations) {
    auto info = info_.find(obs.landmark_id);
    if (info == info_.end()) continue;
    if (t_us_ - info->second.last_seen_us >= min_age_us) {
      pending_loop_.emplace(obs.landmark_id, t_us_);
      ++r.loop_landmarks;
    }
    info->second.last_seen_us = t_us_;
    if (pending_loop_.count(obs.landmark_id)) loop_ids_.push_back(obs.landmark_id);
  }
  std::sort(loop_ids_.begin(), loop_ids_.end());
  Selection rest = loop_ids_.empty() ? Selection::kAll : Selection::kAllButLoop;
  if (o_.slam.loop_closure_min_landmarks > 0 &&
      static_cast<int>(loop_ids_.size()) >= o_.slam.loop_closure_min_landmarks &&
      alignLoop(frame) >= o_.slam.loop_closure_min_landmarks) {
    // Loop closing: the aligned loop landmarks first, ungated, iterated.
    UpdatePolicy ungated = policy_;
    ungated.gate_probability = 0.0;
    const int loop_passes = o_.slam.loop_closure_passes;
    for (int pass = 0; pass < loop_passes; ++pass) {
      UpdateReport u;
      if (Status s = updatePass(frame, loop_passes, Selection::kOnlyLoop, ungated, &u); !s.ok()) {
        return s;
      }
      if (pass + 1 == loop_passes) stats_.add(u);
      r.theta_reduced = r.theta_reduced || u.theta_reduced;
    }
    r.loop_closure = true;
    for (int64_t id : loop_ids_) pending_loop_.erase(id);
  }
  const int passes = o_.slam.observation_passes;
  for (int pass = 0; pass < passes; ++pass) {
    UpdateReport u;
    if (Status s = updatePass(frame, passes, rest, policy_, &u); !s.ok()) return s;
    if (u.observations_accepted + u.observations_rejected > 0) stats_.add(u);
    r.updated = u.observations_accepted;
    r.rejected = u.observations_rejected;
    r.theta_reduced = r.theta_reduced || u.theta_reduced;
  }
  if (Status s = initialiseNew(frame, &r); !s.ok()) return s;
  r.state_size = state_.size();
  r.landmarks_in_state = state_.landmarkCount();
  return Status::Ok();
}

Eigen::VectorXd VisualInertialSlam::vehicleState() const {
  return state_.value(*state_.find(vehicle_));
}

Eigen::MatrixXd VisualInertialSlam::vehicleCovariance() const {
  return state_.covarianceOf(*state_.find(vehicle_));
}

std::vector<MapLandmark> VisualInertialSlam::map() const {
  std::vector<MapLandmark> out;
  for (const StateVariable& v : state_.variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    MapLandmark m;
    m.id = static_cast<int64_t>(v.key.id);
    auto it = info_.find(m.id);
    if (it != info_.end()) m.index = it->second.index;
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
