#pragma once
// Where the filter takes its Jacobians when that is not the estimate: the true state, in
// simulation only — the "ideal EKF" of the consistency literature (Huang, Mourikis &
// Roumeliotis, IJRR 2010, §V). The residuals stay at the estimate; Φ of the propagation, H of
// the stereo update and the Jacobians of a new landmark's initialisation are taken at the
// truth. A filter that is inconsistent even so has a modelling error (noise, timing, data used
// twice, map management); one that is consistent only so is inconsistent by its linearisation.
// A diagnostic: `cvslam_run --linearise-at-truth` (docs/results/ideal_ekf.md); an agent never
// has one.

#include <Eigen/Core>
#include <cstdint>

#include "cvslam/filter/vehicle_model.h"

namespace cvslam {

class LinearisationOracle {
 public:
  virtual ~LinearisationOracle() = default;
  /// The true vehicle state at t_us in the Euler layout [p, v_B, φ θ ψ, b_a, b_g] (15
  /// entries); false when the oracle does not know that time.
  virtual bool vehicleState(int64_t t_us, Eigen::Matrix<double, 15, 1>* x) const = 0;
  /// The true position of landmark `id`; false when it has none (a landmark of another UAV).
  virtual bool landmark(int64_t id, Eigen::Vector3d* p_LinN) const = 0;
};

/// The true pose at t_us with the attitude model of `like` (the estimate's), or false.
bool truePose(const LinearisationOracle& oracle, int64_t t_us, const vehicle_model::Pose& like,
              vehicle_model::Pose* pose);

}  // namespace cvslam
