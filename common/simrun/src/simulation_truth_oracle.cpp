#include "cvslam/simrun/simulation_truth_oracle.h"

#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

void SimulationTruthOracle::setFrameTruth(const sim::GroundTruth& truth) {
  known_[0] = known_[1];
  Known& k = known_[1];
  k.t_us = truth.t_us;
  k.x.head<vehicle::kSizeNoBias>() = truth.eulerLayout();
  k.x.segment<3>(vehicle::kAccelBias) = truth.accel_bias;
  k.x.segment<3>(vehicle::kGyroBias) = truth.gyro_bias;
}

bool SimulationTruthOracle::vehicleState(int64_t t_us, Eigen::Matrix<double, 15, 1>* x) const {
  for (const Known& k : known_) {
    if (k.t_us == t_us) {
      *x = k.x;
      return true;
    }
  }
  return false;
}

}  // namespace cvslam
