#include "cvslam/insgps/gps_aided_ekf.h"

#include <Eigen/Cholesky>

#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

Status EkfOptions::load(const ConfigNode& node) {
  node.get("joseph_form", joseph_form);
  node.get("innovation_gate", innovation_gate);
  node.check(innovation_gate >= 0.0, "innovation_gate", "must be >= 0 (0: no gate)");
  return node.status();
}

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

GpsAidedEkf::GpsAidedEkf(const InsPropagatorOptions& ins, const EkfOptions& options)
    : propagator_(insgpsPropagatorOptions(ins)), o_(options) {}

void GpsAidedEkf::initialize(const StateVector& x0, const StateMatrix& P0, int64_t /*t_us*/) {
  x_ = x0;
  P_ = P0;
  rejected_ = 0;
}

Status GpsAidedEkf::predict(const ImuSample& s0, const ImuSample& s1, double noise_scale) {
  Eigen::VectorXd x_next;
  Eigen::MatrixXd F, G, Q_w;
  const Eigen::VectorXd x = x_;
  Status st = propagator_.step(x, s0, s1, &x_next, &F, &G, &Q_w);
  if (!st.ok()) return st;
  x_ = wrapYaw(x_next);
  P_ = F * P_ * F.transpose() + noise_scale * G * Q_w * G.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return Status::Ok();
}

Status GpsAidedEkf::propagate(const ImuSample& s0, const ImuSample& s1) {
  return predict(s0, s1, 1.0);
}

Status GpsAidedEkf::update(const GpsFix& fix) {
  const MeasVector r = gpsMeasurement(fix) - gpsPredicted(x_);
  StateVector dx;
  if (!kalmanCorrect(r, gpsJacobian(x_), gpsCovariance(fix), o_.joseph_form, o_.innovation_gate,
                     &dx, &P_)) {
    ++rejected_;
    return Status::Ok();
  }
  x_ = wrapYaw(x_ + dx);
  return Status::Ok();
}

}  // namespace cvslam::insgps
