#include "cvslam/insgps/gps_aided_ekf.h"

#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

Status EkfOptions::load(const ConfigNode& node) {
  node.get("joseph_form", joseph_form);
  node.get("innovation_gate", innovation_gate);
  node.check(innovation_gate >= 0.0, "innovation_gate", "must be >= 0 (0: no gate)");
  return node.status();
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
  const MeasVector r = insgps::gpsMeasurement(fix) - gpsPredicted(x_);
  StateVector dx;
  if (!kalmanCorrect(r, gpsJacobian(x_), insgps::gpsCovariance(fix), o_.joseph_form,
                     o_.innovation_gate, &dx, &P_)) {
    ++rejected_;
    return Status::Ok();
  }
  x_ = wrapYaw(x_ + dx);
  return Status::Ok();
}

}  // namespace cvslam::insgps
