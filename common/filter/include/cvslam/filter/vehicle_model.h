#pragma once
// The vehicle block of a SlamState as the SLAM models see it: the ONE place outside the INS
// (ins/ins_propagator.h) that knows how the vehicle's state is parametrised
// (ins/vehicle_state_layout.h: position, body velocity, attitude, optional biases;
// docs/conventions.md, docs/filter.md). The stereo updater, the landmark initialiser, the loop
// closer, the CI updater, CovarianceHelper's mean correction, the map prediction, the front
// end's motion prior and the run record reach the vehicle block only through these functions,
// for any VariableKey::vehicle(i) of the state.
//
// Attitude: a vehicle with a nominal rotation in the state
// (SlamState::nominalAttitude) has the rotation error state — its three attitude entries are
// δθ with R_BtoN = R̂ · Exp(δθ) (right, body-frame perturbation), zero between updates —
// otherwise they are the thesis's ZYX Euler angles. The block keeps its size (9/15) and slot
// layout in both, so additive updates, CI, the covariance algebra and the landmark code are
// the same for both. `correct` folds δθ into R̂ after every update and zeroes it; the reset
// Jacobian ∂δθ⁺/∂δθ = I − ½[δθ]× is taken as I (|δθ| of one update is ≪ 1 rad, as in
// OpenVINS and MSCKF implementations).
//
// Outside the estimator, vehicle states travel in the thesis's Euler layout (run record,
// agent_state_t, gs_state_t; docs/transport.md): `eulerLayout` derives φ θ ψ from R̂ and maps
// the covariance by ∂e/∂δθ; `addVehicle` takes that layout in (∂δθ/∂e).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cvslam/core/status.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/ins/estimated_pose.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam::vehicle_model {

/// Entries of the pose Jacobians the camera model returns: [p_BinN, v_B, attitude].
constexpr int kPoseSize = 9;
using Pose = EstimatedPose;

/// The camera model's pose of the vehicle block (bias states do not enter the observation).
Pose pose(const SlamState& state, const StateVariable& vehicle);

/// The parametrisation of the vehicle's attitude in `state`.
vehicle::Attitude attitudeOf(const SlamState& state, const VariableKey& vehicle);

/// The nominal rotation R̂ the INS propagates from (identity for Euler angles).
Eigen::Quaterniond nominalAttitude(const SlamState& state, const VariableKey& vehicle);

/// After the INS propagated the block: sets the nominal rotation it ended at (no-op for a
/// vehicle with Euler angles).
void setNominalAttitude(SlamState& state, const VariableKey& vehicle,
                        const Eigen::Quaterniond& q_BtoN);

/// Adds a vehicle block from a mean and covariance in the Euler layout [p, v_B, φ θ ψ, (b)]
/// with the attitude parametrised as `attitude` (error state: R̂ = R(φ θ ψ), δθ = 0,
/// P mapped by ∂δθ/∂e).
Status addVehicle(SlamState& state, const VariableKey& vehicle, const Eigen::VectorXd& x_euler,
                  const Eigen::MatrixXd& P_euler, vehicle::Attitude attitude);

/// Adds an error-state vehicle block at the rotation q_BtoN: x_v's attitude entries are
/// ignored (δθ = 0) and P_v is in the error coordinates (any attitude, e.g. IMU x axis up).
Status addVehicle(SlamState& state, const VariableKey& vehicle, const Eigen::VectorXd& x_v,
                  const Eigen::Quaterniond& q_BtoN, const Eigen::MatrixXd& P_v);

/// Covariance of δθ (body frame) for an attitude uncertainty P_N given about N's axes (tilt
/// about x and y, heading about z): R̂ Exp(δθ) = Exp(R̂ δθ) R̂, so P_δθ = R̂ᵀ P_N R̂.
Eigen::Matrix3d errorCovarianceFromNav(const Eigen::Quaterniond& q_BtoN,
                                       const Eigen::Matrix3d& P_N);

/// The vehicle's mean and covariance in the Euler layout (for the run record and messages).
/// At pitch ±90° φ and ψ are split arbitrarily and their variances are large, not infinite.
void eulerLayout(const SlamState& state, const StateVariable& vehicle, Eigen::VectorXd* x,
                 Eigen::MatrixXd* P);

/// Sets ∂h/∂x_v of one observation group of `batch` from ∂h/∂pose (4 × kPoseSize): the
/// Jacobian w.r.t. the vehicle block (bias columns zero).
void setPoseJacobian(MeasurementBatch& batch, int group, const StateVariable& vehicle,
                     const Eigen::Matrix<double, 4, kPoseSize>& dz_dpose);

/// ∂y/∂x_v (3 × vehicle size, bias columns left as they are: zero) from ∂y/∂pose (3 × 9), for
/// a landmark y triangulated from the pose.
void poseToBlockJacobian(const Eigen::Matrix<double, 3, kPoseSize>& dy_dpose,
                         Eigen::MatrixXd* dy_dblock);

/// Applies an additive correction dx_v to the vehicle block x_v (the update's x ← x + δx).
/// nominal == nullptr (Euler angles): keeps roll and yaw in (−π, π]. Otherwise folds the
/// corrected δθ into *nominal (R̂ ← R̂ Exp(δθ)) and zeroes it.
void correct(Eigen::Ref<Eigen::VectorXd> x_v, const Eigen::Ref<const Eigen::VectorXd>& dx_v,
             Eigen::Quaterniond* nominal);

/// The inverse of `correct`: dx_v with correct(x_b, dx_v, nominal_b) = x_a (x_a ⊟ x_b), for two
/// values of one vehicle block. Euler: x_a − x_b with the angle differences in (−π, π].
/// Error state (both nominals given, δθ = 0 in both): Log(R̂_bᵀ R̂_a) on the attitude entries.
Eigen::VectorXd difference(const Eigen::Ref<const Eigen::VectorXd>& x_a,
                           const Eigen::Quaterniond* nominal_a,
                           const Eigen::Ref<const Eigen::VectorXd>& x_b,
                           const Eigen::Quaterniond* nominal_b);
/// Moves the vehicle rigidly: its position to `position`, its heading by `delta_yaw` about
/// N's z axis (the first linearisation point of a loop or rendezvous update). Velocity (body
/// frame), tilt and biases are unchanged.
void moveRigidly(SlamState& state, const StateVariable& vehicle, const Eigen::Vector3d& position,
                 double delta_yaw);

/// M = ∂ξθ/∂a: how the attitude entries a of the block at `pose` turn the vehicle about N's
/// axes, R(a + da) ≈ Exp(M da) R(a). Euler: R(e) W(e) (W = ∂δθ/∂e); error state: R̂.
Eigen::Matrix3d navRotationPerAttitude(const Pose& pose);

/// u_v: how the vehicle block (size `block_size`) at `pose` moves per radian of global yaw
/// (observability_constraint.h): e3 × p for the position, and for the attitude 1 on ψ (Euler)
/// or R̂ᵀ e3 (error state: Rz(α) R̂ = R̂ Exp(α R̂ᵀ e3)); 0 elsewhere.
Eigen::VectorXd yawDirection(const Pose& pose, int block_size);

/// The tracked u_v (propagated by Φ, moved with loop corrections) with its attitude part taken at
/// `pose`, where the Jacobians it constrains are evaluated. Euler: u_v unchanged (its ψ entry
/// is 1 at any attitude). Error state: R̂ᵀ e3 — every update folds δθ into R̂, which turns
/// the body-frame yaw axis; a stale one would let the observations inform global yaw.
Eigen::VectorXd yawDirectionAt(const Pose& pose, const Eigen::VectorXd& u_v);

}  // namespace cvslam::vehicle_model
