#include "cvslam/insgps/riccati.h"

#include <Eigen/LU>
#include <cmath>

namespace cvslam::insgps {

Expected<RiccatiResult> solveFilterDare(const StateMatrix& Phi, const MeasJacobian& H,
                                        const MeasMatrix& R, const StateMatrix& Q,
                                        const RiccatiOptions& o) {
  StateMatrix A = Phi.transpose();
  StateMatrix G = H.transpose() * R.inverse() * H;
  StateMatrix X = Q;
  const StateMatrix I = StateMatrix::Identity();
  for (int k = 1; k <= o.max_iterations; ++k) {
    const Eigen::PartialPivLU<StateMatrix> W(I + G * X);
    const StateMatrix WinvA = W.solve(A);
    const StateMatrix X_next = X + A.transpose() * X * WinvA;
    const StateMatrix G_next = G + A * W.solve(G) * A.transpose();
    A = A * WinvA;
    // Max-abs norms: Frobenius norms overflow to inf on a diverging X and would compare equal.
    const double change = (X_next - X).cwiseAbs().maxCoeff();
    X = 0.5 * (X_next + X_next.transpose());
    G = 0.5 * (G_next + G_next.transpose());
    if (!X.allFinite()) return Status::Error("riccati: doubling diverged (not detectable?)");
    if (change <= o.tolerance * X.cwiseAbs().maxCoeff()) return RiccatiResult{X, k};
  }
  return Status::Error("riccati: no convergence in " + std::to_string(o.max_iterations) +
                       " doubling steps");
}

StateMatrix filterDareResidual(const StateMatrix& P, const StateMatrix& Phi, const MeasJacobian& H,
                               const MeasMatrix& R, const StateMatrix& Q) {
  const MeasMatrix S = H * P * H.transpose() + R;
  const StateMatrix rhs = Phi * P * Phi.transpose() -
                          Phi * P * H.transpose() * S.inverse() * H * P * Phi.transpose() + Q;
  return rhs - P;
}

}  // namespace cvslam::insgps
