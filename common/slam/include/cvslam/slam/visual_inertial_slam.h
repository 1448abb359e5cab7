#pragma once
// One UAV's stereo-inertial VSLAM (thesis chapter 5): INS prediction at IMU rate (§5.3),
// stereo updates of re-observed landmarks (§5.4, §5.5), initialisation of new landmarks by
// the inverse observation model with proper augmentation, k-nearest map management with an
// archive (§5.8) whose re-observed landmarks are re-activated (loop closing, §5.5.2), and
// optional n-fold observation processing (§5.7.3). EKF or NH∞ per FilterOptions (§3.4, §3.6).
//
// Per camera epoch (processFrame), the recipe is:
//   1. propagate the vehicle through the buffered IMU samples to the frame time;
//   2. place the virtual point m* (§5.8) at the median stereo depth of the observations;
//   3. candidates = landmarks in the state ∪ archived landmarks observed now; keep the k
//      nearest to m*, archive the other state landmarks, re-activate the chosen archived ones;
//   4. update with every observation of a landmark in the state (χ²-gated), n passes;
//   5. initialise the observations of never-seen landmarks (at most max_new per frame).
// Observations name their landmark by `landmark_id` (front-end association, or the true id
// in feature-level simulation); landmark_id < 0 means a new landmark, which gets a fresh id.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/slam/k_nearest_map_manager.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/observability_constraint.h"

namespace cvslam {

class ConfigNode;

/// Options of the SLAM recipe itself (config section `slam:`).
struct SlamOptions {
  double pixel_sigma = 0.5;  ///< assumed 1σ of each pixel coordinate of z [px] (R = σ² I₄)
  /// n-fold observation processing (thesis §5.7.3): each frame's observations are processed
  /// this many times, relinearising between passes.
  int observation_passes = 1;
  /// With n passes, use R·n in each pass so that the information of one observation is
  /// counted once (an iterated update). false: the thesis's literal n updates with R.
  bool scale_noise_per_pass = true;
  int max_new_landmarks_per_frame = 8;  ///< new landmarks initialised per frame, nearest to m*
  double min_init_disparity_px = 1.0;   ///< farther points (smaller disparity) are not mapped
  /// An archived landmark re-enters the state only when it left it at least this long ago
  /// [s]. It re-enters with its archived marginal covariance and no correlation to the
  /// vehicle; that is nearly right after a long excursion (loop closing, §5.5.2) but badly
  /// over-confident for a landmark archived a moment ago, whose error is still the vehicle's.
  /// Observations of more recently archived landmarks are not used.
  double reactivation_min_age_s = 10.0;
  /// A landmark observed again after at least this long unseen is a loop landmark [s]
  /// (whether it was archived meanwhile or, with the full map, stayed in the state).
  double loop_closure_min_age_s = 30.0;
  /// First-estimates Jacobians (Huang, Mourikis & Roumeliotis 2008): linearise each
  /// landmark's observations at the estimate it had when it entered the state, so that
  /// successive updates cannot fabricate information about the unobservable yaw and
  /// translation — the main cause of EKF-SLAM over-confidence (cf. thesis §5.7.3, Rco < 1).
  bool first_estimate_jacobians = true;
  /// Observability-constrained updates (observability_constraint.h): every observation
  /// Jacobian is projected so that it cannot inform the global translation and yaw, along
  /// directions carried through the filter's own transitions. Without it, the changing
  /// linearisation points make the yaw look observable and the filter over-confident.
  bool observability_constrained = true;
  /// Loop closing (§5.5.2): landmarks seen again after at least loop_closure_min_age_s
  /// re-locate a drifted vehicle, often by far more than the χ² gate allows. When at least
  /// this many are observed in one frame and a rigid yaw + translation aligns where the
  /// cameras see them with where the map has them (loop_alignment.h), the vehicle and the
  /// recent landmarks are moved by that alignment (the linearisation point) and the loop
  /// landmarks are applied before the other observations, ungated, with iterated passes.
  /// 0 disables this (loop landmarks are then gated like the others).
  int loop_closure_min_landmarks = 3;
  double loop_closure_max_residual_m = 2.0;  ///< loop landmarks farther off the fit are dropped [m]
  int loop_closure_passes = 3;               ///< iterated passes for the loop-closing update
  /// Loop landmarks that find no consensus within this time return to the gated updates [s].
  double loop_closure_window_s = 5.0;
  double initial_accel_bias_sigma = 0.05;  ///< 1σ of the initial accel bias state [m/s²]
  double initial_gyro_bias_sigma = 0.001;  ///< 1σ of the initial gyro bias state [rad/s]
  /// Initial estimate of the accelerometer / gyro bias states (body frame): zero for a
  /// calibrated IMU (thesis); a real one's turn-on bias, e.g. measured at rest before take-off
  /// (the MH_03 recording's gyro bias is 0.077 rad/s, 77 σ of the default above).
  Eigen::Vector3d initial_accel_bias = Eigen::Vector3d::Zero();  ///< [m/s²]
  Eigen::Vector3d initial_gyro_bias = Eigen::Vector3d::Zero();   ///< [rad/s]

  Status load(const ConfigNode& node);
};

/// Everything configurable about one agent's VSLAM (agent.yaml sections).
struct VisualInertialSlamOptions {
  FilterOptions filter;      ///< `filter:`
  InsPropagatorOptions ins;  ///< `ins:`
  MapManagerOptions map;     ///< `map:`
  SlamOptions slam;          ///< `slam:`

  Status load(const ConfigNode& root);
};

/// What one processed frame did.
struct FrameReport {
  int64_t t_us = 0;
  int observations = 0;
  int updated = 0;         ///< observations accepted by the update (last pass)
  int rejected = 0;        ///< observations rejected by the χ² gate (last pass)
  int initialised = 0;     ///< new landmarks added to the state
  int archived = 0;        ///< landmarks moved from the state to the archive
  int reactivated = 0;     ///< archived landmarks brought back into the state
  int loop_landmarks = 0;  ///< landmarks observed again after loop_closure_min_age_s unseen
  bool loop_closure = false;
  bool theta_reduced = false;  ///< NH∞: eq. 3.40 forced a smaller θ in this frame
  int state_size = 0;          ///< after the frame
  int landmarks_in_state = 0;  ///< after the frame
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
  bool initialized() const { return initialized_; }

  /// Buffers an IMU sample; the vehicle is propagated lazily at the next frame.
  Status addImu(const ImuSample& sample);
  /// Propagates to the frame time and runs the recipe above.
  Status processFrame(const StereoFrameObservations& frame, FrameReport* report = nullptr);
  /// Propagates the vehicle through the buffered IMU samples to t_us (step 1 of the recipe;
  /// processFrame at the same time then does not propagate again). Used to predict the map's
  /// observations for association before the frame is processed (map_prediction.h).
  Status propagateTo(int64_t t_us);
  /// Stored descriptor of a landmark in the state or the archive; nullptr if none.
  const std::vector<uint8_t>* descriptorOf(int64_t landmark_id) const;

  int64_t time() const { return t_us_; }
  /// Vehicle state and its covariance block.
  Eigen::VectorXd vehicleState() const;
  Eigen::MatrixXd vehicleCovariance() const;
  const SlamState& state() const { return state_; }
  /// Landmarks in the state, sorted by id.
  std::vector<StateLandmark> stateLandmarks() const;
  /// Covariance-intersection update with a peer's estimates y (3 per landmark, stacked in the
  /// order of `ids`, all in the state) whose covariance is bounded by R (docs/cooperation.md, thesis
  /// eq. 6.2 on the joint state): P⁻¹ ← ω1 P⁻¹ + ω2 Hᵀ R⁻¹ H, i.e. the prior is scaled by 1/ω1
  /// and y enters as a measurement with covariance R/ω2, ω2 = 1 − ω1, so the vehicle and the
  /// other landmarks are corrected through their correlations. omega1 ∈ (0, 1]; 1 = no-op.
  Status fuseCovarianceIntersection(const std::vector<int64_t>& ids, const Eigen::VectorXd& y,
                                    const Eigen::MatrixXd& R, double omega1);
  const LandmarkArchive& archive() const { return archive_; }
  /// Landmarks in the state and in the archive, sorted by id.
  std::vector<MapLandmark> map() const;
  const FilterStatistics& statistics() const { return stats_; }
  /// Switches first-estimates Jacobians (SlamOptions) from the next update on; the first
  /// estimates are always recorded, so this is safe at any time. The image path sets it from
  /// `frontend.first_estimate_jacobians` (visual_slam_pipeline.h).
  void setFirstEstimateJacobians(bool on) { o_.slam.first_estimate_jacobians = on; }
  /// The same for the observability-constrained updates (SlamOptions): their bookkeeping is
  /// always kept, only the projection of the Jacobians is switched.
  void setObservabilityConstrained(bool on) { o_.slam.observability_constrained = on; }
  const VisualInertialSlamOptions& options() const { return o_; }
  const StereoCamera& camera() const { return camera_; }

 private:
  void manageMap(const StereoFrameObservations& frame, FrameReport* report);
  /// Which observations an update pass uses.
  enum class Selection { kAll, kOnlyLoop, kAllButLoop };
  Status updatePass(const StereoFrameObservations& frame, int passes, Selection selection,
                    const UpdatePolicy& policy, UpdateReport* report);
  /// Aligns the loop landmarks, keeps those that fit, moves the linearisation point;
  /// returns how many were kept.
  int alignLoop(const StereoFrameObservations& frame);
  Status initialiseNew(const StereoFrameObservations& frame, FrameReport* report);
  Eigen::Matrix<double, 9, 1> pose9() const;

  VisualInertialSlamOptions o_;
  StereoCamera camera_;
  InsPropagator propagator_;
  KNearestMapManager map_manager_;
  UpdatePolicy policy_;
  Status policy_status_;
  VariableKey vehicle_ = VariableKey::vehicle(0);
  SlamState state_;
  LandmarkArchive archive_;
  MeasurementBatch batch_;             // reused every pass
  std::vector<ImuSample> imu_buffer_;  // front() is at the state time
  Eigen::VectorXd yaw_direction_;      // vehicle's u_v, carried by the transitions (OC-EKF)
  struct LandmarkInfo {
    uint32_t index = 0;
    int64_t first_seen_us = 0;
    int64_t last_seen_us = 0;
    std::vector<uint8_t> descriptor;
    Eigen::Vector3d first_estimate = Eigen::Vector3d::Zero();  ///< p_LinN when (re)entering
    Eigen::Vector3d yaw_direction = Eigen::Vector3d::Zero();   ///< u_L (OC-EKF)
    /// OC-EKF applies: the landmark entered by augmentation, correlated with the vehicle. A
    /// re-activated landmark re-enters without correlation, as an independent prior on its
    /// absolute position, so the joint null space no longer contains it.
    bool constrained = false;
  };
  std::unordered_map<int64_t, LandmarkInfo> info_;  // landmarks in the state
  // Landmarks seen again after a long absence, not yet used to close a loop -> since when.
  std::map<int64_t, int64_t> pending_loop_;
  std::vector<int64_t> loop_ids_;  // pending loop landmarks observed in the current frame
  FilterStatistics stats_;
  int64_t t_us_ = 0;
  int64_t next_fresh_id_ = int64_t{1} << 40;  // ids for landmarks the front end left unnamed
  bool initialized_ = false;
};

}  // namespace cvslam
