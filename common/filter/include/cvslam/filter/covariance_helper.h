#pragma once
// All covariance algebra of the filters, in one stateless place (as OpenVINS's
// StateHelper). Propagators and updaters build (Φ, Q) or (H, r, R) and hand them over; this
// class is the only code that changes SlamState's covariance or its set of variables.
//
// Equations (n: state size, v: the propagated vehicle block, o: every other variable):
//   propagate   P_vv ← Φ P_vv Φᵀ + c_w² Q,   P_vo ← Φ P_vo                 (eq. 3.20)
//   update      EKF, Joseph form (eq. 3.22, 3.23); NH∞ per UpdatePolicy (eq. 3.39, 3.48)
//   augment     y = g(x, z):  P_yy = J_x P J_xᵀ + J_z R J_zᵀ,  P_yx = J_x P
//   marginalise drop the variable's rows and columns (exact for a Gaussian)
//   hold        a landmark becomes a Schmidt (consider) variable and back: the key changes, the
//               slot, the mean and every covariance entry stay (slam_state.h, kHeldLandmark)

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"

namespace cvslam {

/// How CovarianceHelper::iteratedUpdate iterates and gates.
struct IteratedUpdateOptions {
  int max_iterations = 3;  ///< linearisations (1: an EKF update at the given point)
  /// Stop when an iteration moves the estimate by less than this in every entry [state units].
  double step_tolerance = 1e-6;
  /// Gate on the joint NIS of all rows at the last linearisation: the update is not applied
  /// when NIS > χ²_rows(p). 0 disables it.
  double joint_gate_probability = 0.0;
};

class CovarianceHelper {
 public:
  CovarianceHelper() = delete;

  /// Appends a variable independent of the rest (prior mean and covariance).
  static Status addVariable(SlamState& state, const VariableKey& key, const Eigen::VectorXd& value,
                            const Eigen::MatrixXd& covariance);

  /// Appends y = g(x, z) with dy_dx (y.size × state.size, dense) and dy_dz, z ~ N(ẑ, R_z).
  static Status augment(SlamState& state, const VariableKey& key, const Eigen::VectorXd& value,
                        const Eigen::MatrixXd& dy_dx, const Eigen::MatrixXd& dy_dz,
                        const Eigen::MatrixXd& R_z);

  /// The same when y depends on one existing variable only (a landmark triangulated from the
  /// vehicle pose and a stereo observation): O(n) instead of O(n²) in the Jacobian product.
  static Status augment(SlamState& state, const VariableKey& key, const Eigen::VectorXd& value,
                        const VariableKey& source, const Eigen::MatrixXd& dy_dsource,
                        const Eigen::MatrixXd& dy_dz, const Eigen::MatrixXd& R_z);

  /// Removes a variable (marginalisation) and compacts the indices of those after it.
  static Status marginalize(SlamState& state, const VariableKey& key);

  /// Gives variable `from` the key `to` (same slot, mean and covariance): a landmark held as a
  /// Schmidt variable (kHeldLandmark) and back. `to` must not be in the state.
  static Status rekey(SlamState& state, const VariableKey& from, const VariableKey& to);

  /// Joint covariance of the listed variables, in the order given.
  static Expected<Eigen::MatrixXd> marginalCovariance(const SlamState& state,
                                                      const std::vector<VariableKey>& keys);

  /// Replaces the mean of `vehicle` by `value` and propagates the covariance with the
  /// transition Φ = ∂x_v(new)/∂x_v(old) and process noise Qd (already G Q Gᵀ), scaled by the
  /// policy's c_w². Cross-covariances with every other variable follow.
  static Status propagate(SlamState& state, const VariableKey& vehicle,
                          const Eigen::VectorXd& value, const Eigen::MatrixXd& Phi,
                          const Eigen::MatrixXd& Qd, const UpdatePolicy& policy);

  /// P ← factor · P. Covariance intersection scales the local prior by 1/ω₁ before fusing a
  /// peer estimate (thesis eq. 6.5, docs/cooperation.md). factor must be > 0.
  static Status scaleCovariance(SlamState& state, double factor);
  /// The same for the variables `keys` only (one vehicle's subsystem of a joint state):
  /// P ← D P D with D = √factor on their rows and 1 elsewhere, i.e. their block × factor, their
  /// cross-covariances with the other variables × √factor (positive semidefinite preserved).
  /// With every variable listed this is factor · P, the other variables' block is untouched.
  static Status scaleCovariance(SlamState& state, const std::vector<VariableKey>& keys,
                                double factor);

  /// Measurement update with a stacked (H, r, R): gates each observation (Mahalanobis), then
  /// applies the EKF (θ = 0) or NH∞ update. Held landmarks (kHeldLandmark) get a zero gain:
  /// the Schmidt–Kalman update, whose Joseph form keeps their mean and covariance and updates
  /// their cross-covariances exactly. `report` may be null.
  static Status update(SlamState& state, const MeasurementBatch& batch, const UpdatePolicy& policy,
                       UpdateReport* report);

  /// Fills `batch` with z − h(at) and H = ∂h/∂x at `at`, a state with the same variables.
  using Linearisation = std::function<Status(const SlamState& at, MeasurementBatch* batch)>;
  /// Iterated EKF update (Gauss–Newton on the MAP cost; Bell & Cathey 1993), for a measurement
  /// whose prediction at the prior mean is far off (loop closing, rendezvous). Iteration i
  /// linearises at x_i (x_0 = `start`, e.g. the prior moved by a rigid alignment) and updates
  /// the PRIOR with r = z − h(x_i) − H (x_prior ⊟ x_i): x_{i+1} = x_prior ⊞ K_i r. Any shift of
  /// the estimate comes through the gain, so the covariance pays for it, and the joint NIS
  /// at the last x_i tests the whole measurement against the prior (options). The state is
  /// left as it was when the joint gate rejects (report->rejected_jointly) or no observation
  /// remains; per-observation gating follows `policy` in every iteration.
  static Status iteratedUpdate(SlamState& state, SlamState start, const Linearisation& linearise,
                               const IteratedUpdateOptions& options, const UpdatePolicy& policy,
                               MeasurementBatch* batch, UpdateReport* report);
  /// a ⊟ b over the whole state (the vehicles through vehicle_model::difference); a and b must
  /// hold the same variables in the same slots.
  static Expected<Eigen::VectorXd> difference(const SlamState& a, const SlamState& b);

 private:
  /// x ← x + dx; a vehicle block through vehicle_model::correct (angles kept in (−π, π], or
  /// the rotation error folded into the nominal, P's attitude rows and columns mapped by the
  /// reset Jacobian J_r(δθ̂)).
  /// In the right-invariant chart (slam_state.h) P is then mapped from the chart at the prior
  /// mean to the chart at the corrected one (invariant_chart_transport.h).
  /// `anchor`: in the right-invariant chart, the vehicle whose rotation error the errors of
  /// landmarks without an anchor of their own take (SlamState::landmarkAnchor; the observing
  /// vehicle; null: the first).
  static void correctMean(SlamState& state, const Eigen::VectorXd& dx,
                          const VariableKey* anchor = nullptr);
  static Status append(SlamState& state, const VariableKey& key, const Eigen::VectorXd& value);
};

}  // namespace cvslam
