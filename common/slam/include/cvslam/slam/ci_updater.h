#pragma once
// Covariance-intersection update of one vehicle's map with a peer's estimates of some of its
// landmarks (thesis §6.6.4, eq. 6.2 on the joint state; docs/cooperation.md), and the choice of
// the weight ω1 of the own estimate (filter/covariance_intersection.h).
//
// The update: P⁻¹ ← ω1 P⁻¹ + ω2 Hᵀ R⁻¹ H (ω1 = ω2 = 1 for independent estimates), i.e. the prior of
// the vehicle's map (its block, its landmarks and its held landmarks, landmark_book.h) is scaled by
// 1/ω1 and the peer's stacked estimates y enter as a measurement with covariance R/ω2, ω2 = 1 − ω1,
// so the vehicle and its other landmarks are corrected through their correlations. In a state
// holding several vehicles only that vehicle's map and the held landmarks are scaled
// (CovarianceHelper::scaleCovariance over those variables); held landmarks are a per-agent
// state's own.
//
// The weight: adaptive (eq. 6.5 with per-landmark mean traces and both vehicles' position
// covariance traces), fast (eq. 6.4), optimal_trace / optimal_determinant (of the fused
// landmark covariance) or optimal_vehicle (of the fused vehicle position covariance), clamped
// to [min_omega, 1]. Whether the update shrinks the vehicle's position covariance at all is
// reported with it (DcCooperationOptions::require_vehicle_gain).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "cvslam/core/status.h"
#include "cvslam/filter/covariance_intersection.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/slam/landmark_book.h"

namespace cvslam {

/// How ω1 is chosen (config `coop:` ci_method and min_omega, coop/dc_cooperation.h).
struct CiWeighting {
  CiMethod method = CiMethod::kAdaptive;
  double min_omega = 0.05;  ///< smallest ω1: ω1 → 0 would scale the local prior by 1/ω1 → ∞
  /// The peer's estimates are independent of the state (applyIndependent): no ω to choose.
  bool independent = false;
};

/// A peer's estimates of landmarks of the vehicle's map.
struct CiPeerEstimates {
  std::vector<int64_t> ids;    ///< local landmark ids, all in the state
  Eigen::VectorXd y;           ///< peer's positions, 3 per landmark in the order of ids [m]
  Eigen::MatrixXd R;           ///< bound on the covariance of y [m²]
  double vehicle_trace = 0.0;  ///< trace of the peer's vehicle position covariance [m²]
};

/// The chosen weight and what it does to the vehicle.
struct CiChoice {
  double omega1 = 1.0;             ///< weight of the own estimate, in [min_omega, 1]
  double own_vehicle_trace = 0.0;  ///< trace of the own vehicle position covariance [m²]
  bool vehicle_gain = false;       ///< the update shrinks that trace
};

class CiUpdater {
 public:
  explicit CiUpdater(const VariableKey& vehicle) : vehicle_(vehicle) {}

  /// ω1 for fusing `peer` into the vehicle's map of `state`.
  Expected<CiChoice> choose(const SlamState& state, const CiPeerEstimates& peer,
                            const CiWeighting& weighting) const;

  /// The CI update with estimates y (3 per landmark, in the order of `ids`, all in the state
  /// and in `book`) bounded by R, weight omega1 ∈ (0, 1] (1: no-op). Ungated: the caller has
  /// confirmed every landmark. Restarts the book's first estimates at the fused means.
  Status apply(SlamState& state, LandmarkBook& book, const std::vector<int64_t>& ids,
               const Eigen::VectorXd& y, const Eigen::MatrixXd& R, double omega1) const;

  /// The same update for estimates KNOWN to be independent of the state (no information in
  /// common, dc_cooperation.h "provenance"): P⁻¹ ← P⁻¹ + Hᵀ R⁻¹ H, the EKF update, nothing
  /// scaled. R must bound the covariance of y.
  Status applyIndependent(SlamState& state, LandmarkBook& book, const std::vector<int64_t>& ids,
                          const Eigen::VectorXd& y, const Eigen::MatrixXd& R) const;

  const VariableKey& vehicle() const { return vehicle_; }

 private:
  /// The landmarks' variables; an error on a size mismatch, non-finite input or unknown id.
  Expected<std::vector<const StateVariable*>> validate(const SlamState& state,
                                                       const std::vector<int64_t>& ids,
                                                       const Eigen::VectorXd& y,
                                                       const Eigen::MatrixXd& R) const;
  /// Scales the vehicle's map prior by prior_scale, then the EKF update with r_scale·R.
  Status update(SlamState& state, LandmarkBook& book, const std::vector<int64_t>& ids,
                const Eigen::VectorXd& y, const Eigen::MatrixXd& R, double prior_scale,
                double r_scale) const;

  VariableKey vehicle_;
};

}  // namespace cvslam
