#pragma once
// The stereo update of one vehicle (thesis §5.4, §5.5; step 4 of visual_inertial_slam.h): its
// stereo observations of landmarks in the state, stacked into one χ²-gated EKF or NH∞ update
// (UpdatePolicy, §3.4, §3.6), n passes relinearising in between (§5.7.3). The observation model
// is the vehicle's camera (eq. 5.20) at its pose (filter/vehicle_model.h); the landmark book
// supplies the first estimates (first-estimates Jacobians) and the yaw directions of the
// observability-constrained projection (observability_constraint.h). Options: R may carry the
// prediction's second-order term (slam.second_order_noise, stereo_second_order_noise.h); a
// simulation diagnostic may put H at the truth (setOracle, linearisation_oracle.h).
// Works on VariableKey::vehicle(i) of a state that may hold several vehicles: the Jacobian has
// entries in that vehicle's block and the observed landmarks' only.

#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/slam_options.h"

namespace cvslam {

class LinearisationOracle;

class StereoUpdater {
 public:
  /// Which observations the passes use, by their landmark's membership in a sorted id list
  /// (the loop landmarks of loop_closer.h).
  enum class Selection { kAll, kOnlyListed, kAllButListed };

  StereoUpdater(const VariableKey& vehicle, const StereoCamera& camera, const SlamOptions& options);

  /// `passes` update passes with the frame's observations of landmarks in the state (those
  /// of unknown or out-of-state landmarks, and landmarks predicted behind the camera, are
  /// skipped). Each pass uses R = σ² I₄ (× passes with scale_noise_per_pass). The report of
  /// every completed pass is appended to *reports (when a pass fails, those before it).
  Status update(SlamState& state, const LandmarkBook& book, const StereoFrameObservations& frame,
                int passes, Selection selection, const std::vector<int64_t>& listed,
                const UpdatePolicy& policy, std::vector<UpdateReport>* reports);

  /// Jacobians of `linearise`: the filter's (first estimates and the observability constraint
  /// as the options say), or the plain ∂h/∂x at the linearisation point (iterated updates).
  enum class Jacobians { kFilter, kPlain };

  /// Fills `batch` with the selected observations' z − h(x) and H at the state `at` (R = σ² I₄
  /// × noise_scale). Observations of landmarks not in `at` or predicted behind the camera are
  /// left out.
  Status linearise(const SlamState& at, const LandmarkBook& book,
                   const StereoFrameObservations& frame, Selection selection,
                   const std::vector<int64_t>& listed, Jacobians jacobians, double noise_scale,
                   MeasurementBatch* batch) const;

  const VariableKey& vehicle() const { return vehicle_; }
  /// Jacobians (kFilter and kPlain) at the truth (linearisation_oracle.h; simulation
  /// diagnostics); null: off.
  void setOracle(const LinearisationOracle* oracle) { oracle_ = oracle; }

 private:
  VariableKey vehicle_;
  StereoCamera camera_;
  SlamOptions o_;
  MeasurementBatch batch_;  // reused every pass
  const LinearisationOracle* oracle_ = nullptr;
};

}  // namespace cvslam
