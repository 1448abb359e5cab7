#pragma once
// One UAV's stereo-inertial VSLAM (thesis chapter 5): INS prediction at IMU rate (§5.3),
// stereo updates of re-observed landmarks (§5.4, §5.5), initialisation of new landmarks by
// the inverse observation model with proper augmentation, k-nearest map management with an
// archive (§5.8) whose re-observed landmarks are re-activated (loop closing, §5.5.2), and
// optional n-fold observation processing (§5.7.3). EKF or NH∞ per FilterOptions (§3.4, §3.6).
//
// Per camera epoch (processFrame), the recipe over the models of the vehicle, which share its
// landmark book (landmark_book.h) and work on vehicle(i) of any SlamState, is:
//   1. propagate the vehicle through the buffered IMU samples to the frame time (InsPropagator);
//   2. place the virtual point m* (§5.8) at the median stereo depth of the observations;
//   3. candidates = landmarks in the state ∪ archived landmarks observed now; keep the k
//      nearest to m*, archive the other state landmarks, re-activate the chosen archived ones
//      (KNearestMapManager, LandmarkArchive);
//   4. close a loop when enough loop landmarks agree (LoopCloser, loop_closer.h), then update
//      with every other observation of a landmark in the state (StereoUpdater,
//      stereo_updater.h: χ²-gated, n passes);
//   5. initialise the observations of never-seen landmarks, at most max_new per frame
//      (LandmarkInitialiser, landmark_initialiser.h).
// Between frames, cooperation fuses a peer's estimates through the CI updater (ci_updater.h).
// Observations name their landmark by `landmark_id` (front-end association, or the true id
// in feature-level simulation); landmark_id < 0 means a new landmark, which gets a fresh id.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/ins/imu_noise_monitor.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/slam/ci_updater.h"
#include "cvslam/slam/gps_updater.h"
#include "cvslam/slam/k_nearest_map_manager.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/landmark_initialiser.h"
#include "cvslam/slam/loop_closer.h"
#include "cvslam/slam/reactivation_intersection.h"
#include "cvslam/slam/slam_options.h"
#include "cvslam/slam/stereo_updater.h"
#include "cvslam/slam/vehicle_propagation.h"

namespace cvslam {

class ConfigNode;
class LinearisationOracle;

/// Everything configurable about one agent's VSLAM (agent.yaml sections).
struct VisualInertialSlamOptions {
  FilterOptions filter;      ///< `filter:`
  InsPropagatorOptions ins;  ///< `ins:`
  MapManagerOptions map;     ///< `map:`
  SlamOptions slam;          ///< `slam:`
  GpsUpdateOptions gps;      ///< `gps:` (off unless enabled)

  Status load(const ConfigNode& root);
};

/// What one processed frame did.
struct FrameReport {
  int64_t t_us = 0;
  int observations = 0;
  int updated = 0;   ///< observations accepted by the update (last pass)
  int rejected = 0;  ///< observations rejected by the χ² gate (last pass)
  /// Joint NIS rᵀS⁻¹r of the accepted observations (last pass), χ² with nis_dof dof when the
  /// filter is consistent: a check that needs no ground truth (docs/run_format.md events.csv).
  double nis = 0.0;
  int nis_dof = 0;
  int initialised = 0;     ///< new landmarks added to the state
  int archived = 0;        ///< landmarks moved from the state to the archive
  int reactivated = 0;     ///< archived landmarks brought back into the state
  int loop_landmarks = 0;  ///< landmarks observed again after loop_closure_min_age_s unseen
  bool loop_closure = false;
  bool loop_refused = false;   ///< loop landmarks aligned but refused by the joint NIS gate
  bool theta_reduced = false;  ///< NH∞: eq. 3.40 forced a smaller θ in this frame
  int state_size = 0;          ///< after the frame
  int landmarks_in_state = 0;  ///< after the frame
  /// Wall time of the filter's parts [ms] (stats.json stage_ms filter.*): the INS prediction
  /// to the frame time, map management (k nearest, archive, re-activation), the updates (loop
  /// closing and the observed landmarks), the initialisation of new landmarks.
  double predict_ms = 0.0, map_ms = 0.0, update_ms = 0.0, initialise_ms = 0.0;
};

/// A landmark of the agent's map (in the state or archived).
struct MapLandmark {
  int64_t id = -1;
  uint32_t index = 0;
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool in_state = false;
};

/// A landmark in the filter state, with what cooperation needs (thesis §6.6.5).
struct StateLandmark {
  int64_t id = -1;
  uint32_t index = 0;  ///< feature index (visual word, or true id in feature-level simulation)
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< marginal P_LL
  std::vector<uint8_t> descriptor;                       ///< empty: none
  int64_t last_seen_us = 0;                              ///< time of the last observation
};

class VisualInertialSlam {
 public:
  VisualInertialSlam(const VisualInertialSlamOptions& options, const StereoCamera& camera);

  /// Starts the filter at t_us with the vehicle state (9 or 15 entries, matching
  /// options.ins.estimate_imu_bias) and its covariance.
  Status initialize(int64_t t_us, const Eigen::VectorXd& x_v, const Eigen::MatrixXd& P_v);
  /// The same at the rotation q_BtoN (options.ins.attitude must be error_state): x_v's
  /// attitude entries are ignored and P_v's are in the error coordinates δθ.
  Status initialize(int64_t t_us, const Eigen::VectorXd& x_v, const Eigen::Quaterniond& q_BtoN,
                    const Eigen::MatrixXd& P_v);
  bool initialized() const { return initialized_; }

  /// Buffers an IMU sample; the vehicle is propagated lazily at the next frame.
  Status addImu(const ImuSample& sample);
  /// Propagates to the frame time and runs the recipe above.
  Status processFrame(const StereoFrameObservations& frame, FrameReport* report = nullptr);
  /// Propagates the vehicle through the buffered IMU samples to t_us (step 1 of the recipe;
  /// processFrame at the same time then does not propagate again). Used to predict the map's
  /// observations for association before the frame is processed (map_prediction.h).
  Status propagateTo(int64_t t_us);
  /// A GPS fix (gps_updater.h): propagates the vehicle through the buffered IMU to the fix's
  /// time and updates it with the fix. Ok and nothing done when options.gps.enabled is false;
  /// an error for a fix older than the filter's time (feed fixes before the frame after them).
  Status addGps(const GpsFix& fix, UpdateReport* report = nullptr);
  /// Stored descriptor of a landmark in the state or the archive; nullptr if none.
  const std::vector<uint8_t>* descriptorOf(int64_t landmark_id) const;

  int64_t time() const { return t_us_; }
  /// Vehicle state and its covariance block in the Euler layout [p, v_B, φ θ ψ, (b)]
  /// (vehicle_model::eulerLayout: derived from the nominal rotation in error-state mode).
  Eigen::VectorXd vehicleState() const;
  Eigen::MatrixXd vehicleCovariance() const;
  /// The vehicle's pose (rotation-based; vehicle_model::pose).
  vehicle_model::Pose vehiclePose() const;
  const SlamState& state() const { return state_; }
  /// Landmarks in the state, sorted by id.
  std::vector<StateLandmark> stateLandmarks() const;
  /// Covariance-intersection update with a peer's estimates y (3 per landmark, stacked in the
  /// order of `ids`, all in the state) whose covariance is bounded by R: the CI updater
  /// (ci_updater.h) on this filter's state and landmark book. omega1 ∈ (0, 1]; 1 = no-op.
  Status fuseCovarianceIntersection(const std::vector<int64_t>& ids, const Eigen::VectorXd& y,
                                    const Eigen::MatrixXd& R, double omega1);
  /// The EKF update with a peer's estimates known to be independent of this filter's
  /// (CiUpdater::applyIndependent); R bounds their covariance.
  Status fuseIndependent(const std::vector<int64_t>& ids, const Eigen::VectorXd& y,
                         const Eigen::MatrixXd& R);
  /// True when `obs` (of the frame just processed) is of no landmark this filter knows: unnamed
  /// (landmark_id < 0, a point the front end did not offer), or named but neither in the state
  /// nor archived (held included).
  bool isUnmapped(const StereoObservation& obs) const;
  /// Where mapping `obs` now would put its landmark and the marginal covariance it would have
  /// (LandmarkInitialiser::triangulate); false when it cannot be triangulated.
  bool triangulate(const StereoObservation& obs, Eigen::Vector3d* p_LinN,
                   Eigen::Matrix3d* covariance) const;
  /// Maps the unmapped observations of `frame` (the frame just processed) as new landmarks now,
  /// beyond max_new_landmarks_per_frame: the points the cooperation matched to a peer's
  /// landmarks (dc_cooperation.h), so that the peer's estimates can be fused into them. `ids`
  /// gets, per observation, the id of its new landmark (an unnamed one gets a fresh id), or -1.
  Status mapObservations(const StereoFrameObservations& frame, std::vector<int64_t>* ids);
  /// The CI updater of this filter's vehicle (its ω choice reads state()).
  const CiUpdater& ciUpdater() const { return ci_updater_; }
  const LandmarkBook& landmarkBook() const { return book_; }
  const LandmarkArchive& archive() const { return archive_; }
  /// Landmarks in the state and in the archive, sorted by id.
  std::vector<MapLandmark> map() const;
  const FilterStatistics& statistics() const { return stats_; }
  /// Takes the measurement-model switches of `slam` (first-estimate Jacobians, observability
  /// constraint, second-order noise and mean, pixel σ) from the next update on; the first
  /// estimates and the constraint's bookkeeping are always kept, so this is safe at any time.
  /// The image path applies its overrides so, once (VisualFrontEndOptions::resolve).
  void setMeasurementModel(const SlamOptions& slam);
  /// Takes the Jacobians of propagation, stereo update and initialisation at the truth the
  /// oracle gives (linearisation_oracle.h: the ideal EKF, a diagnostic of simulation; null:
  /// off); the loop update's iterated Jacobians too. The oracle must outlive this filter.
  void setLinearisationOracle(const LinearisationOracle* oracle);
  const VisualInertialSlamOptions& options() const { return o_; }
  /// The INS process model, with the noise it assumes now (ins.measure_noise_density).
  const InsPropagator& insModel() const { return propagator_; }
  const StereoCamera& camera() const { return camera_; }

 private:
  Status initializeVehicle(int64_t t_us, const Eigen::VectorXd& x_v,
                           const Eigen::Quaterniond* q_BtoN, const Eigen::MatrixXd& P_v);
  Status manageMap(const StereoFrameObservations& frame, FrameReport* report);
  /// Step 4: the gated stereo updates of the observations not used by loop closing.
  Status updateObserved(const StereoFrameObservations& frame, FrameReport* report);
  /// (Re)creates the models from the options (after a setter changed them).
  void configureModels();
  /// The state's error chart: the configured one, additive under a linearisation oracle.
  ErrorChart chart() const;

  VisualInertialSlamOptions o_;
  StereoCamera camera_;
  InsPropagator propagator_;
  ImuNoiseMonitor noise_monitor_;  // the IMU's in-flight noise (ins.measure_noise_density)
  KNearestMapManager map_manager_;
  UpdatePolicy policy_;
  Status policy_status_;
  VariableKey vehicle_ = VariableKey::vehicle(0);
  SlamState state_;
  LandmarkArchive archive_;
  LandmarkBook book_;  // the landmarks in the state
  StereoUpdater updater_;
  LandmarkInitialiser initialiser_;
  LoopCloser loop_closer_;
  ReactivationIntersection reactivation_;
  CiUpdater ci_updater_;
  GpsUpdater gps_updater_;
  VehiclePropagation propagation_;  // the IMU buffer of step 1
  FilterStatistics stats_;
  int64_t t_us_ = 0;
  const LinearisationOracle* oracle_ = nullptr;
  int64_t next_fresh_id_ = int64_t{1} << 40;  // ids for landmarks the front end left unnamed
  bool initialized_ = false;
};

}  // namespace cvslam
