#include "cvslam/insgps/sdre_filter.h"

#include <Eigen/Cholesky>
#include <unsupported/Eigen/MatrixFunctions>

#include "cvslam/geometry/euler.h"
#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/insgps/kalman_correction.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

Status SdreOptions::load(const ConfigNode& node) {
  node.get("alpha", alpha);
  node.get("riccati_discount", riccati_discount);
  node.get("process_noise_scale", process_noise_scale);
  node.check(process_noise_scale >= 1.0, "process_noise_scale", "must be >= 1");
  node.get("riccati_max_iterations", riccati.max_iterations);
  node.get("riccati_tolerance", riccati.tolerance);
  node.get("sdc_small_coordinate", sdc.small_coordinate);
  node.get("sdc_derivative_step", sdc.derivative_step);
  node.check(riccati_discount > 0.0 && riccati_discount <= 1.0, "riccati_discount",
             "must be in (0, 1]");
  node.check(riccati.max_iterations >= 1, "riccati_max_iterations", "must be >= 1");
  node.check(riccati.tolerance > 0.0, "riccati_tolerance", "must be > 0");
  node.check(sdc.small_coordinate > 0.0, "sdc_small_coordinate", "must be > 0");
  node.check(sdc.derivative_step > 0.0, "sdc_derivative_step", "must be > 0");
  return node.status();
}

SdreFilter::SdreFilter(const InsPropagatorOptions& ins, const SdreOptions& options)
    : propagator_(insgpsPropagatorOptions(ins)), o_(options) {}

void SdreFilter::initialize(const StateVector& x0, const StateMatrix& P0, int64_t /*t_us*/) {
  x_ = x0;
  P_post_ = P0;
  Q_acc_.setZero();
  T_ = 0.0;
  have_imu_ = false;
}

Status SdreFilter::propagate(const ImuSample& s0, const ImuSample& s1) {
  const double dt = 1e-6 * static_cast<double>(s1.t_us - s0.t_us);
  if (!(dt > 0.0) || dt > propagator_.options().max_dt)
    return Status::Error("sdre: IMU interval out of range (" + std::to_string(dt) + " s)");
  const Eigen::VectorXd x = x_;
  const Eigen::VectorXd w = Eigen::VectorXd::Zero(kNoiseSize);
  x_ = wrapYaw(StateVector(propagator_.stepMean(x, s0, s1, w)));
  // Noise input of the dynamics, Γ = ∂f/∂w (exact: f is affine in w): accelerometer noise
  // enters v̇_B as −n_a, gyro noise as n_g × v_B = −[v_B]× n_g and ė as −E(φ θ) n_g (eq. 2.4).
  Eigen::Matrix<double, kStateSize, kNoiseSize> Gamma =
      Eigen::Matrix<double, kStateSize, kNoiseSize>::Zero();
  const Eigen::Vector3d v = x_.segment<3>(vehicle::kVelocity);
  const Eigen::Vector3d euler = x_.segment<3>(vehicle::kAttitude);
  Gamma.block<3, 3>(vehicle::kVelocity, 0) = -Eigen::Matrix3d::Identity();
  Gamma.block<3, 3>(vehicle::kVelocity, 3) << 0.0, v.z(), -v.y(), -v.z(), 0.0, v.x(), v.y(), -v.x(),
      0.0;
  for (int i = 0; i < 3; ++i)
    Gamma.block<3, 1>(vehicle::kAttitude, 3 + i) =
        -eulerRates(euler, Eigen::Vector3d(Eigen::Vector3d::Unit(i)));
  Eigen::Matrix<double, kNoiseSize, 1> q_c;
  const auto& io = propagator_.options();
  q_c << Eigen::Vector3d::Constant(io.accel_noise_density * io.accel_noise_density),
      Eigen::Vector3d::Constant(io.gyro_noise_density * io.gyro_noise_density);
  Q_acc_ += Gamma * q_c.asDiagonal() * Gamma.transpose() * dt;
  T_ += dt;
  last_imu_ = s1;
  have_imu_ = true;
  return Status::Ok();
}

Status SdreFilter::update(const GpsFix& fix) {
  // No motion since the last fix (e.g. a fix at the start): no Riccati pair to solve.
  if (!have_imu_ || T_ <= 0.0) return Status::Ok();
  const InsSdc sdc = insSdc(x_, last_imu_, propagator_.options().gravity, o_.alpha, o_.sdc);
  const StateMatrix A_T = sdc.A * T_;
  const StateMatrix Phi = o_.riccati_discount * A_T.exp();
  const MeasMatrix R = insgps::gpsCovariance(fix);
  const Expected<RiccatiResult> dare =
      solveFilterDare(Phi, sdc.H, R, o_.process_noise_scale * Q_acc_, o_.riccati);
  if (!dare.ok()) return dare.status();
  const StateMatrix& P = dare.value().P;
  riccati_iterations_ = dare.value().iterations;
  const MeasMatrix S = sdc.H * P * sdc.H.transpose() + R;
  const Eigen::LDLT<MeasMatrix> S_ldlt(S);
  const Eigen::Matrix<double, kStateSize, kMeasSize> K = S_ldlt.solve(sdc.H * P).transpose();
  x_ = wrapYaw(x_ + K * (insgps::gpsMeasurement(fix) - gpsPredicted(x_)));
  const StateMatrix I_KH = StateMatrix::Identity() - K * sdc.H;
  P_post_ = I_KH * P * I_KH.transpose() + K * R * K.transpose();
  Q_acc_.setZero();
  T_ = 0.0;
  return Status::Ok();
}

}  // namespace cvslam::insgps
