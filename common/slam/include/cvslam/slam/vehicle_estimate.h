#pragma once
// A vehicle's estimate at one time: the vehicle block of a filter state and its covariance
// (layout of filter/vehicle_model.h: 9 or 15 entries). What the ground station's joint filter
// hands back per UAV (coop/cc_team_filter.h) and what an agent in centralised mode adopts and
// records in place of its own filter's estimate (agent_run_recorder.h).

#include <Eigen/Core>
#include <cstdint>

namespace cvslam {

struct VehicleEstimate {
  int64_t t_us = 0;     ///< time of the estimate [µs]
  Eigen::VectorXd x_v;  ///< vehicle state
  Eigen::MatrixXd P_v;  ///< its covariance block
};

}  // namespace cvslam
