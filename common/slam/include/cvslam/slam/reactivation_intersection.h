#pragma once
// Re-activation of archived landmarks by covariance intersection.
//
// An archived landmark (landmark_archive.h) keeps the marginal covariance Q it had when it left
// the state; its correlation with the state since then is lost. The thesis (§5.8) re-enters it
// uncorrelated, as if its estimate were independent of the vehicle's. It is not: most of Q is the
// vehicle's own uncertainty of that time along the unobservable directions (global translation
// and yaw), which the vehicle still carries. Observed again, such a landmark tells the vehicle
// where it is in the world more precisely than anybody knows, and the covariance collapses: on
// euroc_mh03_hall (features) the position σ fell from 0.10 m to 4 mm in 40 s while the error
// stayed at 0.2 m (vehicle NEES 10⁴; docs/results/consistency_perturbed.md).
//
// For every cross-covariance C of the state x (covariance P) and an archived estimate (Q),
//   [P C; Cᵀ Q] ≤ [P/ω 0; 0 Q/(1−ω)]   for every ω ∈ (0, 1)
// (the covariance-intersection bound, Julier & Uhlmann 1997, which thesis §6.6.4 uses between
// UAVs). So the landmarks of a frame re-enter uncorrelated with Q/(1−ω) while the prior of the
// rest of the state is scaled by 1/ω: a consistent joint prior whatever the lost correlation.
// ω minimises, after the frame's observations of those landmarks, by golden section on
// [min_omega, max_omega], either the log-determinant of the vehicle's whole block (the default;
// in a joint state, of every vehicle's blocks: the team's, the ground station's) or the trace of
// its position covariance (summed over the vehicles); ω → 1 means that the archive adds nothing
// to what the frame sees. Every variable but the re-activated landmarks is scaled: in
// VisualInertialSlam one vehicle's map, in the ground station's joint state (cc_team_filter.h)
// every UAV and the whole joint map. Since each such scaling also widens what the landmarks cannot
// inform (tilt, biases), an agent maps a frame's landmarks anew instead when the update is not
// predicted to shrink its vehicle block by more than the scaling widens it
// (ReactivationOptions::remap_without_gain).

#include <cstdint>
#include <utility>
#include <vector>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/reactivation_options.h"
#include "cvslam/slam/stereo_updater.h"

namespace cvslam {

/// What one frame's re-activation did.
struct ReactivationReport {
  int landmarks = 0;                ///< landmarks moved from the archive to the state
  int remapped = 0;                 ///< taken from the archive to be mapped anew (no gain)
  double omega = 1.0;               ///< weight of the state's prior (1: nothing re-activated)
  double position_trace_prior = 0;  ///< tr of the objective's position covariance before [m²]
  double position_trace_after = 0;  ///< the same after this frame's observations (predicted)
};

class ReactivationIntersection {
 public:
  explicit ReactivationIntersection(ReactivationOptions options) : w_(options) {}

  /// Moves the archived landmarks `ids` into the state and `book` by covariance intersection
  /// with the rest of the state, ω chosen with `updater`'s Jacobians of `frame`. Ids that are
  /// not archived are skipped. ω minimises ReactivationOptions::objective over the
  /// `objective` vehicles (empty: the updater's vehicle alone). With remap_without_gain, ids
  /// without gain leave the archive and the state (the initialiser maps them anew).
  Status reactivate(SlamState& state, LandmarkBook& book, LandmarkArchive& archive,
                    const std::vector<int64_t>& ids, const StereoUpdater& updater,
                    const StereoFrameObservations& frame, ReactivationReport* report,
                    const std::vector<VariableKey>& objective = {});

  /// Trace of the vehicle position covariance after the update (H, R) from the prior
  /// blockdiag(P_A/ω, n·P_B/(1 − ω)), where B are the columns `b_columns` of n landmarks
  /// (3 each, uncorrelated with A in P), summed over the position rows p..p+2 of every p in
  /// `p_indices`: the objective of the weight. Exposed for tests.
  static double positionTraceAfter(const Eigen::MatrixXd& P, const Eigen::MatrixXd& H,
                                   const Eigen::MatrixXd& R, const std::vector<int>& b_columns,
                                   const std::vector<int>& p_indices, double omega);
  /// The same prior and update: the log-determinant of the joint covariance of the blocks
  /// (first index, size) `vehicles` after it (kVehicleLogDet, remap_without_gain).
  static double vehicleLogDetAfter(const Eigen::MatrixXd& P, const Eigen::MatrixXd& H,
                                   const Eigen::MatrixXd& R, const std::vector<int>& b_columns,
                                   const std::vector<std::pair<int, int>>& vehicles, double omega);

 private:
  ReactivationOptions w_;
  MeasurementBatch batch_;  // reused
};

}  // namespace cvslam
