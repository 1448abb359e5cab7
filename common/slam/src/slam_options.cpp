#include "cvslam/slam/slam_options.h"

#include "cvslam/io/config_node.h"

#include <string>
#include <utility>
#include <vector>

namespace cvslam {

Status SlamOptions::checkChart() const {
  // First estimates and the constraint fix the yaw direction of the additive chart; in the
  // invariant chart it is fixed already, and Jacobians at first estimates break it (team3_aerial:
  // vehicle NEES ≈ 900, docs/filter.md "Invariant error chart").
  if (error_chart == ErrorChart::kRightInvariant &&
      (first_estimate_jacobians || observability_constrained)) {
    return Status::Error(
        "right_invariant needs first_estimate_jacobians: false and "
        "observability_constrained: false (they belong to the additive chart)");
  }
  return Status::Ok();
}

Status SlamOptions::load(const ConfigNode& node) {
  node.get("pixel_sigma", pixel_sigma);
  node.get("second_order_noise", second_order_noise);
  node.get("second_order_mean", second_order_mean);
  node.get("observation_passes", observation_passes);
  node.get("scale_noise_per_pass", scale_noise_per_pass);
  node.get("max_new_landmarks_per_frame", max_new_landmarks_per_frame);
  node.get("min_init_disparity_px", min_init_disparity_px);
  node.get("loop_closure_min_age_s", loop_closure_min_age_s);
  node.get("reactivation_min_age_s", reactivation_min_age_s);
  node.check(reactivation_min_age_s >= 0.0, "reactivation_min_age_s", "must be ≥ 0");
  const std::vector<std::pair<std::string, Reentry>> reentries = {
      {"remap", Reentry::kRemap},
      {"intersection", Reentry::kIntersection},
      {"independent", Reentry::kIndependent}};
  node.getEnum("recent_reentry", recent_reentry, reentries);
  node.getEnum("reactivation", reactivation, reentries);
  node.check(reactivation != Reentry::kRemap, "reactivation",
             "must be intersection or independent (loop closing needs the archived estimate)");
  node.get("held_landmarks", held_landmarks);
  node.check(held_landmarks >= 0, "held_landmarks", "must be ≥ 0");
  node.get("anchor_landmarks", anchor_landmarks);
  node.check(anchor_landmarks >= 0, "anchor_landmarks", "must be ≥ 0");
  node.check(anchor_landmarks == 0 || held_landmarks > 0, "anchor_landmarks",
             "needs held_landmarks > 0 (anchors are held landmarks)");
  node.getEnum("held_eviction", held_eviction,
               {{"oldest", HeldEviction::kOldest}, {"nearest", HeldEviction::kNearest}});
  node.get("reactivation_min_omega", intersection.min_omega);
  node.get("reactivation_max_omega", intersection.max_omega);
  node.check(intersection.min_omega > 0.0 && intersection.min_omega <= intersection.max_omega &&
                 intersection.max_omega < 1.0,
             "reactivation_min_omega",
             "need 0 < reactivation_min_omega ≤ reactivation_max_omega < 1");
  node.getEnum("reactivation_objective", intersection.objective,
               {{"position_trace", ReactivationOptions::Objective::kPositionTrace},
                {"vehicle_log_det", ReactivationOptions::Objective::kVehicleLogDet}});
  node.get("reactivation_remap_without_gain", intersection.remap_without_gain);
  node.get("first_estimate_jacobians", first_estimate_jacobians);
  node.get("observability_constrained", observability_constrained);
  node.get("oc_tilt", oc_tilt);
  node.check(!oc_tilt || observability_constrained, "oc_tilt",
             "needs observability_constrained: true (the tilt joins its constraint)");
  node.getEnum("oc_projection", oc_projection,
               {{"range_weighted", OcProjection::kRangeWeighted},
                {"unweighted", OcProjection::kUnweighted}});
  node.getEnum(
      "error_chart", error_chart,
      {{"additive", ErrorChart::kAdditive}, {"right_invariant", ErrorChart::kRightInvariant}});
  if (Status s = checkChart(); !s.ok()) node.check(false, "error_chart", s.message());
  node.get("loop_closure_min_landmarks", loop_closure_min_landmarks);
  node.get("loop_closure_max_residual_m", loop_closure_max_residual_m);
  node.get("loop_closure_passes", loop_closure_passes);
  node.get("loop_closure_gate_probability", loop_closure_gate_probability);
  node.get("loop_closure_window_s", loop_closure_window_s);
  node.check(loop_closure_window_s > 0.0, "loop_closure_window_s", "must be > 0");
  node.check(loop_closure_min_landmarks >= 0, "loop_closure_min_landmarks", "must be ≥ 0");
  node.check(loop_closure_max_residual_m > 0.0, "loop_closure_max_residual_m", "must be > 0");
  node.check(loop_closure_passes >= 1, "loop_closure_passes", "must be ≥ 1");
  node.check(loop_closure_gate_probability >= 0.0 && loop_closure_gate_probability < 1.0,
             "loop_closure_gate_probability", "must be in [0, 1)");
  node.get("initial_accel_bias_sigma", initial_accel_bias_sigma);
  node.get("recorded_accel_bias_sigma", recorded_accel_bias_sigma);
  node.get("initial_gyro_bias_sigma", initial_gyro_bias_sigma);
  node.get("initial_accel_bias", initial_accel_bias);
  node.get("initial_gyro_bias", initial_gyro_bias);
  node.check(initial_accel_bias.allFinite() && initial_gyro_bias.allFinite(), "initial_accel_bias",
             "initial biases must be finite");
  node.check(initial_accel_bias_sigma > 0.0 && initial_gyro_bias_sigma > 0.0,
             "initial_accel_bias_sigma", "initial bias sigmas must be > 0");
  node.check(recorded_accel_bias_sigma > 0.0, "recorded_accel_bias_sigma", "must be > 0");
  node.check(pixel_sigma > 0.0, "pixel_sigma", "must be > 0");
  node.check(observation_passes >= 1, "observation_passes", "must be ≥ 1");
  node.check(max_new_landmarks_per_frame >= 0, "max_new_landmarks_per_frame", "must be ≥ 0");
  node.check(min_init_disparity_px > 0.0, "min_init_disparity_px", "must be > 0");
  node.check(loop_closure_min_age_s >= 0.0, "loop_closure_min_age_s", "must be ≥ 0");
  return node.status();
}

}  // namespace cvslam
