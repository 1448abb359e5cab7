#pragma once
// GPS observation model of the INS/GPS filters on their Euler-angle state: the shared model
// of ins/gps_observation.h (thesis eq. 2.10 with velocity, §2.4) at x = [p, v_B, φ θ ψ]:
//   h(x) = [p_N ; R_BtoN(φ θ ψ) v_B],   R = diag(σ_p², σ_v²) of the fix.

#include "cvslam/insgps/gps_aided_filter.h"

namespace cvslam::insgps {

/// h(x).
MeasVector gpsPredicted(const StateVector& x);
/// ∂h/∂x at x.
MeasJacobian gpsJacobian(const StateVector& x);
/// y = [p_N ; v_N] of a fix.
MeasVector gpsMeasurement(const GpsFix& fix);
/// R = diag(σ_p², σ_v²) of a fix.
MeasMatrix gpsCovariance(const GpsFix& fix);

}  // namespace cvslam::insgps
