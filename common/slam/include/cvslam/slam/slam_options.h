#pragma once
// Options of the chapter-5 recipe itself (config section `slam:`), shared by the SLAM models
// (stereo_updater.h, landmark_initialiser.h, loop_closer.h) and VisualInertialSlam.

#include <Eigen/Core>

#include "cvslam/core/status.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/slam/reactivation_options.h"

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
  /// Add the second-order term of the prediction, ½ tr(∇²h_i P ∇²h_j P), to each stereo
  /// observation's R (the Gaussian second-order filter; stereo_second_order_noise.h): the
  /// linearisation error of landmarks whose depth is still uncertain. config/agent.yaml turns
  /// it on at feature level (docs/filter.md "The second-order term at feature level").
  bool second_order_noise = false;
  /// Predict each stereo observation at its second-order mean, h(x̂) + ½ tr(∇²h_i P) over the
  /// error chart's Gaussian, instead of h(x̂) (the same filter's mean term;
  /// stereo_second_order_noise.h): the curvature of 1/Z biases h(x̂) one way, and the bias
  /// shortens the flown distance (docs/filter.md "The second-order mean").
  bool second_order_mean = false;
  int max_new_landmarks_per_frame = 8;  ///< new landmarks initialised per frame, nearest to m*
  double min_init_disparity_px = 1.0;   ///< farther points (smaller disparity) are not mapped
  /// An archived landmark re-enters the state only when it left it at least this long ago
  /// [s]; observations of more recently archived landmarks are not used. With remap, 0 made
  /// euroc_mh03_hall consistent (median vehicle NEES 10 / 16, 10 seeds) but cost the aerial
  /// scenarios accuracy (team3_aerial UAV3 ATE +15 %) and thesis_loop consistency
  /// (docs/filter.md, "Re-activation").
  double reactivation_min_age_s = 10.0;
  /// How an archived landmark re-enters the state; its correlation with the state is lost.
  ///  - kRemap: it is mapped anew, triangulated by the initialiser from the current frame and
  ///    correlated with the vehicle as it is now; its archived copy is dropped.
  ///  - kIntersection: by covariance intersection with the rest of the state
  ///    (reactivation_intersection.h): consistent whatever the lost correlation.
  ///  - kIndependent: the thesis's (§5.8): its archived marginal, uncorrelated, as if
  ///    independent of the vehicle, whose error of that time it still carries.
  /// `recent_reentry` applies to a landmark seen again less than loop_closure_min_age_s after
  /// it was last seen (a hovering vehicle, a short excursion), `reactivation` to loop landmarks.
  /// kIndependent for recent ones made a hovering UAV over-confident (euroc_mh03_hall UAV1:
  /// position σ 0.10 m → 4 mm at an error of 0.2 m, NEES 2.6·10⁴); kIntersection for loop
  /// landmarks let thesis_loop loops go wrong in the additive chart (seed 303: yaw 9° off);
  /// with the invariant chart's iterated loop update it is the consistent choice and the
  /// default (thesis_loop UAV1 NEES after its loop 5.5 against 145–226 for kIndependent,
  /// seeds 301–320). docs/filter.md, "Re-activation".
  enum class Reentry { kRemap, kIntersection, kIndependent };
  Reentry recent_reentry = Reentry::kRemap;
  Reentry reactivation = Reentry::kIntersection;  ///< kRemap is not allowed: loops need the archive
  /// How many of the most recently archived landmarks stay in the state as held (Schmidt)
  /// variables (slam_state.h, kHeldLandmark): their correlations with the vehicle and the map
  /// are kept, so one that is observed again re-enters exactly, at any age and whatever
  /// recent_reentry / reactivation say, and landmarks swapping in and out of the k nearest
  /// cost neither information nor consistency. Each costs 3 state entries in every update.
  /// 0: the thesis's archive only. 100 chosen on seeds 301–320 and the recordings with
  /// kIntersection re-entry (docs/filter.md, "Re-activation"): the real-IMU recordings
  /// gain from the map they keep exactly (V1_02 9.8 → 7.1 cm); 300 was less consistent on
  /// euroc_mh03_hall (UAV2 NEES 12.9 against 11.7) at 6 ms per frame instead of 1.6.
  int held_landmarks = 100;
  /// Which held landmarks leave first when more than held_landmarks are held:
  ///  - kOldest: those archived longest ago (one vehicle: the ones it left behind first), the
  ///    agents' choice (kNearest cost the recordings accuracy, docs/filter.md "Held landmarks");
  ///  - kNearest: those farthest from every vehicle's latest virtual point m* (§5.8), so the
  ///    capacity goes to the landmarks some vehicle is about to see again. The joint map's
  ///    choice: there five UAVs archive into one pool, and by age each UAV's landmarks left it
  ///    within about 1.5 s (a single agent's 100 last about 7 s).
  enum class HeldEviction { kOldest, kNearest };
  HeldEviction held_eviction = HeldEviction::kOldest;
  /// Older held landmarks kept beyond held_landmarks as anchors spread over the whole map
  /// (landmark_lifecycle.h): when the vehicle comes back after a long absence, a loop landmark
  /// that is an anchor re-enters exactly, with its correlations, instead of by intersection,
  /// which cannot know what the landmark and the vehicle share (docs/filter.md "Anchor
  /// landmarks"). Each costs 3 state entries in every update. 0: none.
  int anchor_landmarks = 0;
  /// kIntersection: the weight ω's bounds and objective, and whether landmarks that bring no
  /// gain are mapped anew (reactivation_options.h).
  ReactivationOptions intersection;
  /// A landmark observed again after at least this long unseen is a loop landmark [s]
  /// (whether it was archived meanwhile or, with the full map, stayed in the state).
  double loop_closure_min_age_s = 30.0;
  /// First-estimates Jacobians (Huang, Mourikis & Roumeliotis 2008): linearise each
  /// landmark's observations at the estimate it had when it entered the state, so that
  /// successive updates cannot fabricate information about the unobservable yaw and
  /// translation — the main cause of EKF-SLAM over-confidence (cf. thesis §5.7.3, Rco < 1).
  /// For the additive chart only (error_chart), where it was the default until the invariant
  /// chart, which fixes the same yaw direction without it (docs/filter.md).
  bool first_estimate_jacobians = false;
  /// Observability-constrained updates (observability_constraint.h): every observation
  /// Jacobian is projected so that it cannot inform the global translation and yaw, along
  /// directions carried through the filter's own transitions. Without it, the changing
  /// linearisation points make the yaw look observable and the filter over-confident.
  /// For the additive chart only, like first_estimate_jacobians.
  bool observability_constrained = false;
  /// How the observability constraint changes a Jacobian (observability_constraint.h):
  /// the smallest change with the attitude columns weighted by the landmark's range
  /// (kRangeWeighted: ∂h/∂attitude and ∂h/∂position on one scale, so the yaw correction lands
  /// mostly on the attitude columns and the relative-position Jacobian keeps its
  /// linearisation), or unweighted (kUnweighted, the earlier behaviour: the change lands on the
  /// position columns). docs/filter.md, "Observability constraint", for the Monte Carlo.
  enum class OcProjection { kRangeWeighted, kUnweighted };
  OcProjection oc_projection = OcProjection::kRangeWeighted;
  /// OC-EKF also for the two tilt axes of each observation: its Jacobian may not inform a
  /// rigid rotation about N's x or y axis of the vehicle and the landmark's first estimate
  /// (observability_constraint.h tiltDirections). Needs observability_constrained.
  bool oc_tilt = false;
  /// The error chart of the covariance (slam_state.h ErrorChart): additive (the thesis's EKF)
  /// or right_invariant (the invariant EKF's: updates keep the covariance of the invariant
  /// error, whose unobservable directions do not depend on the estimate). With it the
  /// filter's own Jacobians stay consistent without first estimates or the constraint;
  /// docs/filter.md "Invariant error chart". The ground station uses it too, each landmark
  /// in the chart of the vehicle that mapped it (CcTeamFilterOptions).
  ErrorChart error_chart = ErrorChart::kRightInvariant;
  /// Loop closing (§5.5.2): landmarks seen again after at least loop_closure_min_age_s
  /// re-locate a drifted vehicle, often by far more than the χ² gate allows. When at least
  /// this many are observed in one frame and a rigid yaw + translation aligns where the
  /// cameras see them with where the map has them (loop_alignment.h), the loop landmarks
  /// enter as an iterated EKF update (CovarianceHelper::iteratedUpdate) linearised first at
  /// the vehicle moved by that alignment, before the other observations. The shift comes
  /// through the gain (the covariance pays for it), and the loop is refused when its joint
  /// NIS fails loop_closure_gate_probability. 0 disables loop closing (loop landmarks are then
  /// gated like the others).
  int loop_closure_min_landmarks = 3;
  double loop_closure_max_residual_m = 2.0;  ///< loop landmarks farther off the fit are dropped [m]
  int loop_closure_passes = 3;  ///< Gauss–Newton iterations (linearisations) of the loop update
  /// χ² probability of the loop update's joint NIS gate (0: no gate).
  double loop_closure_gate_probability = 0.9999;
  /// Loop landmarks that find no consensus within this time return to the gated updates [s].
  double loop_closure_window_s = 5.0;
  double initial_accel_bias_sigma = 0.05;  ///< 1σ of the initial accel bias state [m/s²]
  /// The same for a RECORDED IMU (an EuRoC folder, a scenario's imu.recording), whose turn-on
  /// accelerometer bias nobody drew from the prior: EuRoC's ground truth puts the ADIS16448's at
  /// up to 0.10 m/s² per axis at take-off (V1_01, V1_02). It replaces initial_accel_bias_sigma
  /// for such a start; too small a prior makes the tilt over-confident (σ_tilt → σ_ba / g).
  double recorded_accel_bias_sigma = 0.1;  ///< [m/s²]
  double initial_gyro_bias_sigma = 0.001;  ///< 1σ of the initial gyro bias state [rad/s]
  /// Initial estimate of the accelerometer / gyro bias states (body frame): zero for a
  /// calibrated IMU (thesis); a real one's turn-on bias, e.g. measured at rest before take-off
  /// (the MH_03 recording's gyro bias is 0.077 rad/s, 77 σ of the default above).
  Eigen::Vector3d initial_accel_bias = Eigen::Vector3d::Zero();  ///< [m/s²]
  Eigen::Vector3d initial_gyro_bias = Eigen::Vector3d::Zero();   ///< [rad/s]

  /// Fails when error_chart is right_invariant with first_estimate_jacobians or
  /// observability_constrained (load() checks it; so does VisualInertialSlam for options set
  /// in code).
  Status checkChart() const;
  Status load(const ConfigNode& node);
};

}  // namespace cvslam
