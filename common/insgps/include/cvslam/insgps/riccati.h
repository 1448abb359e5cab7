#pragma once
// Discrete algebraic Riccati equation of the steady-state Kalman filter (the discrete
// counterpart of thesis eq. 3.28), for the SDRE filter:
//   P = Φ P Φᵀ − Φ P Hᵀ (H P Hᵀ + R)⁻¹ H P Φᵀ + Q      (a-priori covariance)
// Solved by the structure-preserving doubling algorithm (SDA; Chu, Fan & Lin 2005), i.e. the
// control DARE X = Aᵀ X (I + G X)⁻¹ A + Q with A = Φᵀ, G = Hᵀ R⁻¹ H:
//   W = I + G_k Q_k,  A_{k+1} = A_k W⁻¹ A_k,  G_{k+1} = G_k + A_k W⁻¹ G_k A_kᵀ,
//   Q_{k+1} = Q_k + A_kᵀ Q_k W⁻¹ A_k,  Q_k → P.
// Why SDA: it converges quadratically (each step doubles the horizon of the underlying
// Riccati recursion, so ~log₂ of the convergence time in steps), needs only 9×9 solves
// (Eigen has no ordered real Schur form for the Hamiltonian/Schur method), and keeps P
// symmetric positive semidefinite. It needs (Φ, H) detectable and (Φ, Q^½) stabilisable;
// the SDRE filter ensures the former with a discount (sdre_filter.h).

#include "cvslam/core/status.h"
#include "cvslam/insgps/gps_aided_filter.h"

namespace cvslam::insgps {

struct RiccatiOptions {
  int max_iterations = 60;   ///< doubling steps (horizon 2^60 steps: never the limit)
  double tolerance = 1e-10;  ///< stop when ‖Q_{k+1} − Q_k‖ ≤ tolerance · ‖Q_{k+1}‖
};

struct RiccatiResult {
  StateMatrix P;
  int iterations = 0;
};

/// The stabilising solution, or an error if the doubling does not converge.
Expected<RiccatiResult> solveFilterDare(const StateMatrix& Phi, const MeasJacobian& H,
                                        const MeasMatrix& R, const StateMatrix& Q,
                                        const RiccatiOptions& o = {});

/// Residual of the DARE at P (for tests and diagnostics): right side minus P.
StateMatrix filterDareResidual(const StateMatrix& P, const StateMatrix& Phi, const MeasJacobian& H,
                               const MeasMatrix& R, const StateMatrix& Q);

}  // namespace cvslam::insgps
