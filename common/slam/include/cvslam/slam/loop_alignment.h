#pragma once
// Rigid 4-DoF alignment for loop closing (thesis §5.5.2).
//
// After a long excursion the vehicle may have drifted by many times its estimated σ, and the
// EKF update with the re-observed old landmarks, linearised at the drifted pose, then goes
// wrong (the projections of the old landmarks can lie far outside the image). Roll and pitch
// stay observable through gravity; the drift is mostly a horizontal shift and a yaw rotation
// (the unobservable directions of visual-inertial SLAM). This aligns the loop landmarks as
// the cameras see them now (stereo triangulation at the current pose) with their archived
// positions by a yaw rotation about the vehicle and a translation — a closed-form 2-D
// Procrustes problem plus the mean vertical offset — and gives the corrected vehicle pose,
// used as the linearisation point of the loop-closing update.

#include <Eigen/Core>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

/// One loop landmark: where the current observation places it and where the map has it.
struct LoopPair {
  Eigen::Vector3d p_observed_N = Eigen::Vector3d::Zero();  ///< triangulated now, in N [m]
  Eigen::Vector3d p_map_N = Eigen::Vector3d::Zero();       ///< archived/map position [m]
};

/// The rigid motion p ↦ pivot + translation + R_z(yaw) (p − pivot) that moves the observed
/// points onto the map points (R_z an active rotation about the down axis, N = NED).
struct LoopAlignment {
  double yaw = 0.0;                                       ///< δψ [rad]
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();        ///< rotation centre [m]
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  ///< [m]
  double rms_residual = 0.0;                              ///< after alignment [m]

  Eigen::Vector3d apply(const Eigen::Vector3d& p) const;
};

/// Least-squares yaw + translation from ≥ 2 pairs, rotating about `pivot` (the vehicle).
Expected<LoopAlignment> alignLoop(const std::vector<LoopPair>& pairs, const Eigen::Vector3d& pivot);

}  // namespace cvslam
