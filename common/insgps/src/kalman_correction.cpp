#include "cvslam/insgps/kalman_correction.h"

#include <Eigen/Cholesky>

namespace cvslam::insgps {

InsPropagatorOptions insgpsPropagatorOptions(InsPropagatorOptions ins) {
  ins.attitude = vehicle::Attitude::kEuler;
  ins.estimate_imu_bias = false;
  return ins;
}

bool kalmanCorrect(const MeasVector& r, const MeasJacobian& H, const MeasMatrix& R,
                   bool joseph_form, double gate, StateVector* dx, StateMatrix* P) {
  const MeasMatrix S = H * (*P) * H.transpose() + R;
  const Eigen::LDLT<MeasMatrix> S_ldlt(S);
  if (gate > 0.0 && r.dot(S_ldlt.solve(r)) > gate) return false;
  // K = P Hᵀ S⁻¹, from S Kᵀ = H P (S and P symmetric).
  const Eigen::Matrix<double, kStateSize, kMeasSize> K = S_ldlt.solve(H * (*P)).transpose();
  *dx = K * r;
  if (joseph_form) {
    const StateMatrix I_KH = StateMatrix::Identity() - K * H;
    *P = I_KH * (*P) * I_KH.transpose() + K * R * K.transpose();
  } else {
    *P -= K * H * (*P);
  }
  *P = 0.5 * (*P + P->transpose()).eval();
  return true;
}

}  // namespace cvslam::insgps
