#include "cvslam/filter/vehicle_model.h"

#include "cvslam/geometry/euler.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam::vehicle_model {

Pose pose(const SlamState& state, const StateVariable& vehicle) {
  return state.value(vehicle).head<kPoseSize>();
}

void setPoseJacobian(MeasurementBatch& batch, int group, const StateVariable& vehicle,
                     const Eigen::Matrix<double, 4, kPoseSize>& dz_dpose) {
  // The pose is the head of the block: its Jacobian is the block's first kPoseSize columns.
  batch.setJacobian(group, vehicle.index, dz_dpose);
}

void poseToBlockJacobian(const Eigen::Matrix<double, 3, kPoseSize>& dy_dpose,
                         Eigen::MatrixXd* dy_dblock) {
  dy_dblock->leftCols<kPoseSize>() = dy_dpose;
}

void correct(Eigen::Ref<Eigen::VectorXd> x_v, const Eigen::Ref<const Eigen::VectorXd>& dx_v) {
  x_v += dx_v;
  if (x_v.size() < vehicle::kSizeNoBias) return;
  x_v(vehicle::kAttitude) = wrapAngle(x_v(vehicle::kAttitude));
  x_v(vehicle::kAttitude + 2) = wrapAngle(x_v(vehicle::kAttitude + 2));
}

void moveRigidly(SlamState& state, const StateVariable& vehicle, const Eigen::Vector3d& position,
                 double delta_yaw) {
  Eigen::VectorXd x_v = state.value(vehicle);
  x_v.segment<3>(vehicle::kPosition) = position;
  x_v(vehicle::kAttitude + 2) = wrapAngle(x_v(vehicle::kAttitude + 2) + delta_yaw);
  state.setValue(vehicle, x_v);
}

Eigen::VectorXd yawDirection(const Eigen::Vector3d& p_BinN, int block_size) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(block_size);
  u.segment<3>(vehicle::kPosition) = Eigen::Vector3d(-p_BinN.y(), p_BinN.x(), 0.0);  // e3 × p
  u(vehicle::kAttitude + 2) = 1.0;  // ZYX Euler: a rotation about N's z adds to ψ only
  return u;
}

}  // namespace cvslam::vehicle_model
