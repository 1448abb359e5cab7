#pragma once
// Loop closing for one vehicle (thesis §5.5.2; SlamOptions loop_closure_*): landmarks of the
// vehicle's map observed again after at least loop_closure_min_age_s unseen are loop landmarks.
// They stay pending (landmark_book.h) for loop_closure_window_s and out of the gated updates,
// where a drifted vehicle would reject them one by one. When at least
// loop_closure_min_landmarks of them are observed in one frame and a rigid yaw + translation
// (loop_alignment.h) aligns where the camera sees them with where the map has them, they enter
// as one iterated EKF update (CovarianceHelper::iteratedUpdate): the first linearisation is at
// the vehicle moved by that alignment, but the update starts from the prior, so the vehicle and
// the landmarks correlated with it move through the gain and the covariance shrinks by exactly
// what the loop tells (the mean is never moved outside the filter). The joint NIS
// of the loop observations against the prior gates the loop (loop_closure_gate_probability):
// a loop the prior covariance cannot explain is refused, not forced. Afterwards the first
// estimates and OC yaw directions of what moved follow it (followCorrection).
// Works on VariableKey::vehicle(i) of a state that may hold several vehicles: every variable
// may move through its correlation with vehicle i; the caller updates the other vehicles'
// books with followCorrection.

#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/loop_alignment.h"
#include "cvslam/slam/slam_options.h"
#include "cvslam/slam/stereo_updater.h"

namespace cvslam {

/// What loop closing did in one frame.
struct LoopReport {
  int loop_landmarks = 0;     ///< landmarks observed again after loop_closure_min_age_s unseen
  bool loop_closure = false;  ///< the loop landmarks were aligned and applied
  bool loop_refused = false;  ///< aligned, but the joint NIS gate refused the loop update
  double nis = 0.0;           ///< joint NIS of the loop update (χ² with nis_dof dof)
  int nis_dof = 0;
  bool theta_reduced = false;  ///< NH∞: eq. 3.40 forced a smaller θ in the loop update
  /// The state's mean before a loop closure (set only when loop_closure), for followCorrection.
  Eigen::VectorXd mean_before;
};

/// After an update that moved the estimate far (a loop closure): the first estimates and OC
/// yaw directions (u = e3 × p, observability_constraint.h) of `book`'s landmarks and of
/// `vehicle` move with their means, so the first-estimate Jacobians keep the geometry they
/// had. `mean_before` is the state's mean before the update (same variables).
void followCorrection(const SlamState& state, const Eigen::VectorXd& mean_before,
                      const VariableKey& vehicle, LandmarkBook* book);

class LoopCloser {
 public:
  LoopCloser(const VariableKey& vehicle, const StereoCamera& camera, const SlamOptions& options);

  /// One frame at t_us: marks the loop landmarks among the observations (and the observed
  /// landmarks of the book as seen at t_us), expires old pending ones, and closes the loop
  /// when enough agree, with `policy` ungated. The statistics of the last loop pass go to
  /// *stats. Afterwards loopIds() are the observations the gated updates must leave out.
  Status process(SlamState& state, LandmarkBook& book, const StereoFrameObservations& frame,
                 int64_t t_us, StereoUpdater& updater, const UpdatePolicy& policy,
                 FilterStatistics* stats, LoopReport* report);

  /// Ids (ascending) of this frame's loop landmarks left out of the gated updates: the pending
  /// ones observed now, or after a loop closure the aligned ones (already applied).
  const std::vector<int64_t>& loopIds() const { return loop_ids_; }

 private:
  /// Marks loop landmarks and last-seen times; fills loop_ids_ with the pending observed ones.
  void detect(LandmarkBook& book, const StereoFrameObservations& frame, int64_t t_us,
              LoopReport* report);
  /// Aligns the loop landmarks and keeps those that fit (loop_ids_); returns how many.
  int align(const SlamState& state, const StereoFrameObservations& frame, LoopAlignment* fit);

  VariableKey vehicle_;
  StereoCamera camera_;
  SlamOptions o_;
  std::vector<int64_t> loop_ids_;  // pending loop landmarks observed in the current frame
  MeasurementBatch batch_;         // reused by the loop updates
};

}  // namespace cvslam
