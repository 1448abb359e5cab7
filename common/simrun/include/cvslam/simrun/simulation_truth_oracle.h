#pragma once
// The simulator's truth as a LinearisationOracle (slam/linearisation_oracle.h): the true
// vehicle state at the agent's last two frames (a propagation runs from the one to the other)
// and the true landmark positions its sensing knows. `cvslam_run --linearise-at-truth`.

#include <array>

#include "cvslam/sim/simulator.h"
#include "cvslam/simrun/frame_sensing.h"
#include "cvslam/slam/linearisation_oracle.h"

namespace cvslam {

class SimulationTruthOracle : public LinearisationOracle {
 public:
  /// `sensing` answers for the landmarks; kept alive by the caller.
  explicit SimulationTruthOracle(const FrameSensing* sensing) : sensing_(sensing) {}
  /// The truth at a new frame, before the filter processes it.
  void setFrameTruth(const sim::GroundTruth& truth);

  bool vehicleState(int64_t t_us, Eigen::Matrix<double, 15, 1>* x) const override;
  bool landmark(int64_t id, Eigen::Vector3d* p_LinN) const override {
    return sensing_->landmarkTruth(id, p_LinN);
  }

 private:
  struct Known {
    int64_t t_us = -1;
    Eigen::Matrix<double, 15, 1> x = Eigen::Matrix<double, 15, 1>::Zero();
  };
  const FrameSensing* sensing_;
  std::array<Known, 2> known_;  // the last two frames, the newest at [1]
};

}  // namespace cvslam
