#include "cvslam/slam/linearisation_oracle.h"

namespace cvslam {

bool truePose(const LinearisationOracle& oracle, int64_t t_us, const vehicle_model::Pose& like,
              vehicle_model::Pose* pose) {
  Eigen::Matrix<double, 15, 1> x;
  if (!oracle.vehicleState(t_us, &x)) return false;
  // R from the true angles; the Jacobian columns in the estimate's attitude coordinates.
  *pose = EstimatedPose::fromEuler(x.head<9>());
  pose->attitude = like.attitude;
  return true;
}

}  // namespace cvslam
