#pragma once
// The vehicle block of a SlamState as the SLAM models see it: the ONE place that knows how the
// vehicle's state is parametrised (ins/vehicle_state_layout.h: position, body velocity, ZYX
// Euler angles, optional biases; docs/conventions.md). The stereo updater, the landmark
// initialiser, the loop closer, the CI updater and CovarianceHelper's mean correction reach the
// vehicle block only through these functions, for any VariableKey::vehicle(i) of the state.
//
// Issue #13 replaces the Euler angles by a rotation error state (quaternion nominal, 3-dof
// error). That change is made here: `pose` then derives the camera model's pose from the
// nominal, `setPoseJacobian` / `poseToBlockJacobian` chain ∂/∂pose into the error state, and
// `correct` becomes the ⊞ of the error state; `moveRigidly` and `yawDirection` follow.
// Outside the models, readers of the vehicle state that #13 points at `pose` as well: the image
// path's map prediction (slam/map_prediction.cpp, pose and its 9×9 covariance block), the
// front end's motion prior (slam/visual_slam_pipeline.cpp), the run record
// (slam/agent_run_recorder.cpp), and the INS propagator (ins/), which owns the transition.

#include <Eigen/Core>

#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"

namespace cvslam::vehicle_model {

/// Entries of the pose the camera model takes (camera/stereo_camera.h): [p_BinN, v_B, euler].
constexpr int kPoseSize = 9;
using Pose = Eigen::Matrix<double, kPoseSize, 1>;

/// The camera model's pose of the vehicle block (bias states do not enter the observation).
Pose pose(const SlamState& state, const StateVariable& vehicle);

/// Sets ∂h/∂x_v of one observation group of `batch` from ∂h/∂pose (4 × kPoseSize): the
/// Jacobian w.r.t. the vehicle block (bias columns zero).
void setPoseJacobian(MeasurementBatch& batch, int group, const StateVariable& vehicle,
                     const Eigen::Matrix<double, 4, kPoseSize>& dz_dpose);

/// ∂y/∂x_v (3 × vehicle size, bias columns left as they are: zero) from ∂y/∂pose (3 × 9), for
/// a landmark y triangulated from the pose.
void poseToBlockJacobian(const Eigen::Matrix<double, 3, kPoseSize>& dy_dpose,
                         Eigen::MatrixXd* dy_dblock);

/// Applies an additive correction dx_v to the vehicle block x_v (the update's x ← x + δx),
/// keeping roll and yaw in (−π, π].
void correct(Eigen::Ref<Eigen::VectorXd> x_v, const Eigen::Ref<const Eigen::VectorXd>& dx_v);

/// Moves the vehicle rigidly: its position to `position`, its heading by `delta_yaw` about
/// N's z axis (the loop alignment, loop_alignment.h). Velocity (body frame), roll, pitch and
/// biases are unchanged.
void moveRigidly(SlamState& state, const StateVariable& vehicle, const Eigen::Vector3d& position,
                 double delta_yaw);

/// u_v: how the vehicle block (size `block_size`) at p_BinN moves per radian of global yaw
/// (observability_constraint.h): e3 × p for the position, 1 for ψ, 0 elsewhere.
Eigen::VectorXd yawDirection(const Eigen::Vector3d& p_BinN, int block_size);

}  // namespace cvslam::vehicle_model
