#pragma once
// The Kalman correction shared by the KF (§3.3, eqs. 3.8–3.12) and the EKF (§3.4, eqs.
// 3.21–3.23), and the propagator options all INS/GPS filters run with.

#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_filter.h"

namespace cvslam::insgps {

/// `ins` with the Euler attitude and no bias states (the thesis's 9-state model), whatever
/// `ins` said: the propagator options of every INS/GPS filter.
InsPropagatorOptions insgpsPropagatorOptions(InsPropagatorOptions ins);

/// Correction of P by the innovation r = y − h(x) with Jacobian H and noise R:
/// K = P Hᵀ (H P Hᵀ + R)⁻¹ (eq. 3.22, with the transpose the thesis omits), *dx = K r, and P
/// by the Joseph form (eq. 3.23, second form) or P − K H P. Returns false (and changes
/// nothing) when gate > 0 and rᵀ S⁻¹ r > gate.
bool kalmanCorrect(const MeasVector& r, const MeasJacobian& H, const MeasMatrix& R,
                   bool joseph_form, double gate, StateVector* dx, StateMatrix* P);

}  // namespace cvslam::insgps
