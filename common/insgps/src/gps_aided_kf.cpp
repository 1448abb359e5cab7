#include "cvslam/insgps/gps_aided_kf.h"

#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/insgps/kalman_correction.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

Status KfOptions::load(const ConfigNode& node) {
  node.get("joseph_form", joseph_form);
  node.get("reset_interval_s", reset_interval_s);
  node.check(reset_interval_s >= 0.0, "reset_interval_s", "must be >= 0 (0: open loop)");
  return node.status();
}

GpsAidedKf::GpsAidedKf(const InsPropagatorOptions& ins, const KfOptions& options)
    : propagator_(insgpsPropagatorOptions(ins)), o_(options) {}

void GpsAidedKf::initialize(const StateVector& x0, const StateMatrix& P0, int64_t t_us) {
  x_ins_ = x0;
  dx_.setZero();
  P_ = P0;
  t_us_ = t_us;
  last_reset_us_ = t_us;
}

Status GpsAidedKf::propagate(const ImuSample& s0, const ImuSample& s1) {
  Eigen::VectorXd x_next;
  Eigen::MatrixXd F, G, Q_w;
  const Eigen::VectorXd x = x_ins_;
  Status st = propagator_.step(x, s0, s1, &x_next, &F, &G, &Q_w);
  if (!st.ok()) return st;
  x_ins_ = wrapYaw(x_next);
  // Eqs. 3.6–3.7 on the error state (no control input: the IMU drives the nominal).
  const StateMatrix Fk = F;
  dx_ = Fk * dx_;
  P_ = Fk * P_ * Fk.transpose() + G * Q_w * G.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  t_us_ = s1.t_us;
  return Status::Ok();
}

Status GpsAidedKf::update(const GpsFix& fix) {
  // z = y − h(x_ins) ≈ H δx + v; innovation z − H δx̂ (eq. 3.8).
  const MeasJacobian H = gpsJacobian(x_ins_);
  const MeasVector r = insgps::gpsMeasurement(fix) - gpsPredicted(x_ins_) - H * dx_;
  StateVector correction;
  kalmanCorrect(r, H, insgps::gpsCovariance(fix), o_.joseph_form, 0.0, &correction, &P_);
  dx_ += correction;
  if (o_.reset_interval_s > 0.0 &&
      1e-6 * static_cast<double>(fix.t_us - last_reset_us_) >= o_.reset_interval_s) {
    x_ins_ = wrapYaw(x_ins_ + dx_);
    dx_.setZero();
    last_reset_us_ = fix.t_us;
  }
  return Status::Ok();
}

}  // namespace cvslam::insgps
