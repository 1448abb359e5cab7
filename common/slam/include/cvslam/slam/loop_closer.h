#pragma once
// Loop closing for one vehicle (thesis §5.5.2; SlamOptions loop_closure_*): landmarks of the
// vehicle's map observed again after at least loop_closure_min_age_s unseen are loop landmarks.
// They stay pending (landmark_book.h) for loop_closure_window_s and out of the gated updates,
// where a drifted vehicle would reject them one by one. When at least
// loop_closure_min_landmarks of them are observed in one frame and a rigid yaw + translation
// (loop_alignment.h) aligns where the camera sees them with where the map has them, the
// vehicle and the recently seen landmarks are moved by that alignment (the linearisation
// point, with their first estimates and OC yaw directions) and the aligned loop landmarks are
// applied first, ungated, with loop_closure_passes iterated passes (stereo_updater.h).
// Works on VariableKey::vehicle(i) of a state that may hold several vehicles: only that
// vehicle and the landmarks of its book move.

#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/slam_options.h"
#include "cvslam/slam/stereo_updater.h"

namespace cvslam {

/// What loop closing did in one frame.
struct LoopReport {
  int loop_landmarks = 0;      ///< landmarks observed again after loop_closure_min_age_s unseen
  bool loop_closure = false;   ///< the loop landmarks were aligned and applied
  bool theta_reduced = false;  ///< NH∞: eq. 3.40 forced a smaller θ in a loop pass
};

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
  /// Aligns the loop landmarks, keeps those that fit, moves the linearisation point;
  /// returns how many were kept.
  int align(SlamState& state, LandmarkBook& book, const StereoFrameObservations& frame,
            int64_t t_us);

  VariableKey vehicle_;
  StereoCamera camera_;
  SlamOptions o_;
  std::vector<int64_t> loop_ids_;  // pending loop landmarks observed in the current frame
};

}  // namespace cvslam
