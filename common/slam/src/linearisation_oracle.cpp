#include "cvslam/slam/linearisation_oracle.h"

#include "cvslam/geometry/euler.h"

namespace cvslam {

bool truePose(const LinearisationOracle& oracle, int64_t t_us, const vehicle_model::Pose& like,
              vehicle_model::Pose* pose) {
  Eigen::Matrix<double, 15, 1> x;
  if (!oracle.vehicleState(t_us, &x)) return false;
  *pose = like;
  pose->p_BinN = x.segment<3>(vehicle::kPosition);
  pose->v_B = x.segment<3>(vehicle::kVelocity);
  pose->euler = x.segment<3>(vehicle::kAttitude);
  pose->R_BtoN = rotationBodyToNav(pose->euler);
  return true;
}

}  // namespace cvslam
