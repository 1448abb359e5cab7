#pragma once
// The GPS observation of a vehicle (thesis eq. 2.10 with velocity, §2.4): one model for the
// chapter-3 INS/GPS filters (insgps/) and the GPS updates of the VSLAM filter
// (slam/gps_updater.h). A receiver at the vehicle origin (no lever arm):
//   z = [p_N; v_N] = h(pose) + n,   h = [p_BinN; R_BtoN v_B],   n ~ N(0, diag(σ_p², σ_v²)).
// Jacobian w.r.t. the pose entries [p, v_B, attitude]: [I 0 0; 0 R ∂(R v_B)/∂attitude], the
// attitude columns being ∂R(φθψ)/∂(φθψ)·v_B for Euler angles (automatic differentiation of the
// INS's own rotation) or −R [v_B]× for the rotation error state (R = R̂ Exp(δθ)).

#include <Eigen/Core>

#include "cvslam/ins/estimated_pose.h"
#include "cvslam/ins/gps_fix.h"

namespace cvslam {

constexpr int kGpsObservationSize = 6;
constexpr int kGpsPoseSize = 9;  ///< [p, v_B, attitude]
using GpsVector = Eigen::Matrix<double, kGpsObservationSize, 1>;
using GpsJacobian = Eigen::Matrix<double, kGpsObservationSize, kGpsPoseSize>;

/// h(pose) = [p_BinN; R_BtoN v_B].
GpsVector gpsPrediction(const EstimatedPose& pose);
/// ∂h/∂[p, v_B, attitude] at `pose`, in the pose's attitude coordinates.
GpsJacobian gpsJacobian(const EstimatedPose& pose);
/// z = [p_N; v_N] of a fix.
GpsVector gpsMeasurement(const GpsFix& fix);
/// diag(σ_p², σ_v²) of a fix (its stated accuracies).
Eigen::Matrix<double, kGpsObservationSize, kGpsObservationSize> gpsCovariance(const GpsFix& fix);

}  // namespace cvslam
