#pragma once
// Predicted stereo observations of an agent's map at the current epoch, for the front end's
// data association (thesis §5.5, §5.5.2; docs/front_end.md): for each landmark that may be in
// view — those in the filter state and the archived ones near the predicted view that the
// filter may re-activate (held in the state, slam.held_landmarks, or archived at least
// slam.reactivation_min_age_s ago), which is what makes map reuse and loop closing possible —
// the predicted measurement ẑ = h(x̂_v, p̂_L) (eq. 5.20)
// and its innovation covariance
//   S = H P Hᵀ + R,  H = [∂h/∂x_v  ∂h/∂p_L],  R = σ_px² I₄,
// where P is the joint covariance of vehicle and landmark (archived landmarks that are not held
// have no correlation with the vehicle left: P_vL = 0), plus the landmark's stored descriptor.
// No OpenCV types: descriptors are byte vectors.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

class ConfigNode;

struct MapPredictionOptions {
  bool include_archived = true;  ///< predict archived landmarks too (loop closing, §5.5.2)
  double max_range_m = 60.0;     ///< landmarks farther from the predicted camera are skipped [m]
  /// A prediction is kept when ẑ_L lies inside the image grown by this margin plus 3σ of the
  /// predicted u/v [px].
  double image_margin_px = 4.0;

  Status load(const ConfigNode& node);
};

struct PredictedObservation {
  int64_t landmark_id = -1;
  Eigen::Vector4d z = Eigen::Vector4d::Zero();       ///< ẑ = [u_L v_L u_R v_R] [px]
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();   ///< innovation covariance [px²]
  const std::vector<uint8_t>* descriptor = nullptr;  ///< owned by the filter; may be empty
  bool archived = false;
};

/// The observations of the map of `slam` at its present time (the frame's: the caller
/// propagated it, VisualInertialSlam::propagateTo), ordered by landmark id. Landmarks behind
/// the camera are skipped. The filter is not changed.
Status predictMapObservations(const VisualInertialSlam& slam, const MapPredictionOptions& options,
                              std::vector<PredictedObservation>* predictions);

}  // namespace cvslam
