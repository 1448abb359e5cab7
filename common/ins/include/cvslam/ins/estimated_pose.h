#pragma once
// The vehicle's pose as the observation models take it (camera/stereo_camera.h): position,
// body velocity and the rotation R_BtoN, plus the coordinates in which the models return
// their attitude Jacobian columns. Built from a SlamState by vehicle_model::pose, so only
// vehicle_model and the INS know how the attitude is stored (vehicle_state_layout.h).

#include <Eigen/Core>

#include "cvslam/geometry/euler.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

struct EstimatedPose {
  Eigen::Vector3d p_BinN = Eigen::Vector3d::Zero();  ///< [m], N
  Eigen::Vector3d v_B = Eigen::Vector3d::Zero();     ///< [m/s], body
  Eigen::Matrix3d R_BtoN = Eigen::Matrix3d::Identity();
  /// kEuler: attitude Jacobian columns are ∂/∂[φ θ ψ] at `euler`, and the models evaluate
  /// R from `euler` exactly as the thesis's model does. kErrorState: ∂/∂δθ at δθ = 0 with
  /// R = R_BtoN · Exp(δθ).
  vehicle::Attitude attitude = vehicle::Attitude::kErrorState;
  Eigen::Vector3d euler = Eigen::Vector3d::Zero();  ///< φ θ ψ [rad], kEuler only

  /// The pose of an Euler-layout state head [p_BinN, v_B, φ θ ψ].
  static EstimatedPose fromEuler(const Eigen::Matrix<double, 9, 1>& x) {
    EstimatedPose pose;
    pose.p_BinN = x.segment<3>(vehicle::kPosition);
    pose.v_B = x.segment<3>(vehicle::kVelocity);
    pose.euler = x.segment<3>(vehicle::kAttitude);
    pose.R_BtoN = rotationBodyToNav(pose.euler);
    pose.attitude = vehicle::Attitude::kEuler;
    return pose;
  }
};

}  // namespace cvslam
