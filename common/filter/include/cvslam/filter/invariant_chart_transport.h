#pragma once
// The change of error coordinates between two estimates in the right-invariant chart
// (slam_state.h, ErrorChart::kRightInvariant; docs/filter.md "Invariant error chart").
//
// The covariance is stored in additive coordinates δ at the mean x̂, but in this chart it is the
// covariance of the invariant error ξ = A(x̂) δ. The same ξ in the coordinates at another
// estimate x̄ is δ̄ = A(x̄)⁻¹ A(x̂) δ =: J δ, with
//   attitude   M̄⁻¹ M̂            (M = ∂ξθ/∂a, vehicle_model::navRotationPerAttitude)
//   velocity   R̄ᵀ R̂             (ξ_v = R̂ δv_B)
//   position   I, and −[p̄ − p̂]× M̂ on the attitude columns
//   landmark   I, and −[l̄ − l̂]× M̂ of the anchor vehicle
// J maps the directions no observation can inform (global translation and yaw) at x̂ to those
// at x̄ exactly. Two uses (CovarianceHelper):
//  - after a correction x̂ → x̄ of the mean, P ← J P Jᵀ (the update kept the covariance of ξ);
//  - an iterated update linearised at x̄ ≠ x̂ uses ∂h/∂δ at x̄ times J, the Jacobian of h with
//    respect to the prior's own coordinates. Without J the iterations' Jacobians see the prior's
//    yaw uncertainty as observable (the additive chart's inconsistency, which a loop closure's
//    metres of correction make large).

#include <Eigen/Core>
#include <vector>

#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/ins/estimated_pose.h"

namespace cvslam {

class InvariantChartTransport {
 public:
  /// J from the estimate (x_from, its vehicles' poses in index order) to `to`'s mean (same
  /// variables in the same slots). A landmark takes the rotation error of its own anchor
  /// (SlamState::landmarkAnchor: the vehicle it was mapped from), else of `anchor` (the
  /// observing vehicle; null or absent: the first vehicle). Identity when `to` has no vehicle.
  InvariantChartTransport(const Eigen::VectorXd& x_from,
                          const std::vector<EstimatedPose>& poses_from, const SlamState& to,
                          const VariableKey* anchor);

  /// The poses of `state`'s vehicles in index order (the "from" poses of a later transport).
  static std::vector<EstimatedPose> vehiclePoses(const SlamState& state);

  /// M ← M Jᵀ (M has the state's size in columns), by columns.
  void multiplyByTransposeFromRight(Eigen::MatrixXd& M) const;
  /// M ← J M (M has the state's size in rows), by rows. P ← J P Jᵀ is this after the one above:
  /// both touch only the rows / columns J moves, O(n) each.
  void multiplyFromLeft(Eigen::MatrixXd& M) const;
  /// H ← H J for the batch's Jacobian; blocks that J fills in are added to the batch's sparsity.
  void multiplyJacobian(MeasurementBatch& batch) const;

 private:
  struct Coupling {
    int row;       // first row of the position or landmark
    int attitude;  // first row of the attitude it couples to
    Eigen::Matrix3d C;
  };
  struct Rotation {
    int row;
    Eigen::Matrix3d R;
  };
  std::vector<Coupling> couplings_;
  std::vector<Rotation> rotations_;  // velocity and attitude blocks
};

/// The vehicle whose rotation error the landmarks of an invariant-chart update take: the first
/// whose attitude columns `batch` uses (the observer); null when none does.
const VariableKey* observingVehicle(const SlamState& state, const MeasurementBatch& batch);

}  // namespace cvslam
