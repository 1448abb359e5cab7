#include "cvslam/ins/ins_propagator.h"

#include <ceres/jet.h>

#include <cmath>
#include <sstream>
#include <string>

#include "cvslam/io/config_node.h"

namespace cvslam {

Status InsPropagatorOptions::load(const ConfigNode& node) {
  node.get("gyro_noise_density", gyro_noise_density);
  node.get("accel_noise_density", accel_noise_density);
  node.get("gyro_random_walk", gyro_random_walk);
  node.get("accel_random_walk", accel_random_walk);
  node.get("estimate_imu_bias", estimate_imu_bias);
  node.get("gravity", gravity);
  node.get("max_dt", max_dt);
  node.check(gyro_noise_density > 0, "gyro_noise_density", "must be > 0");
  node.check(accel_noise_density > 0, "accel_noise_density", "must be > 0");
  node.check(gyro_random_walk > 0, "gyro_random_walk", "must be > 0");
  node.check(accel_random_walk > 0, "accel_random_walk", "must be > 0");
  node.check(gravity > 0, "gravity", "must be > 0");
  node.check(max_dt > 0, "max_dt", "must be > 0");
  return node.status();
}

std::string InsPropagatorOptions::print() const {
  std::ostringstream os;
  os.precision(17);
  os << "gyro_noise_density: " << gyro_noise_density << "\n"
     << "accel_noise_density: " << accel_noise_density << "\n"
     << "gyro_random_walk: " << gyro_random_walk << "\n"
     << "accel_random_walk: " << accel_random_walk << "\n"
     << "estimate_imu_bias: " << (estimate_imu_bias ? "true" : "false") << "\n"
     << "gravity: " << gravity << "\n"
     << "max_dt: " << max_dt << "\n";
  return os.str();
}

namespace {

/// Classical RK4 from t0 to t0+dt; the IMU input is linear between the samples, so the
/// midpoint stages use the average of the two samples.
template <typename T, int kN>
Eigen::Matrix<T, kN, 1> rk4Step(const Eigen::Matrix<T, kN, 1>& x, const ImuSample& s0,
                                const ImuSample& s1, const Eigen::Matrix<T, kN - 3, 1>& w,
                                double dt, double gravity) {
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  const Vec3 g0 = s0.gyro_B.cast<T>(), a0 = s0.accel_B.cast<T>();
  const Vec3 g1 = s1.gyro_B.cast<T>(), a1 = s1.accel_B.cast<T>();
  const Vec3 gm = (0.5 * (s0.gyro_B + s1.gyro_B)).cast<T>();
  const Vec3 am = (0.5 * (s0.accel_B + s1.accel_B)).cast<T>();
  const T h(dt), half_h(0.5 * dt);
  using Prop = InsPropagator;
  const Eigen::Matrix<T, kN, 1> k1 = Prop::dynamics<T, kN>(x, g0, a0, w, gravity);
  const Eigen::Matrix<T, kN, 1> k2 = Prop::dynamics<T, kN>(x + half_h * k1, gm, am, w, gravity);
  const Eigen::Matrix<T, kN, 1> k3 = Prop::dynamics<T, kN>(x + half_h * k2, gm, am, w, gravity);
  const Eigen::Matrix<T, kN, 1> k4 = Prop::dynamics<T, kN>(x + h * k3, g1, a1, w, gravity);
  return x + (h / T(6.0)) * (k1 + T(2.0) * k2 + T(2.0) * k3 + k4);
}

template <int kN>
Eigen::VectorXd stepMeanFixed(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
                              const Eigen::VectorXd& w, double dt, double gravity) {
  const Eigen::Matrix<double, kN, 1> xf = x;
  const Eigen::Matrix<double, kN - 3, 1> wf = w;
  return rk4Step<double, kN>(xf, s0, s1, wf, dt, gravity);
}

/// The RK4 map evaluated on Jets: one pass gives x₁ and both Jacobians.
template <int kN>
void stepJacobiansFixed(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
                        double dt, double gravity, Eigen::VectorXd* x_next,
                        Eigen::MatrixXd* dx1_dx0, Eigen::MatrixXd* dx1_dw) {
  constexpr int kW = kN - 3;
  using Jet = ceres::Jet<double, kN + kW>;
  Eigen::Matrix<Jet, kN, 1> xj;
  for (int i = 0; i < kN; ++i) xj(i) = Jet(x(i), i);
  Eigen::Matrix<Jet, kW, 1> wj;
  for (int j = 0; j < kW; ++j) wj(j) = Jet(0.0, kN + j);
  const Eigen::Matrix<Jet, kN, 1> x1 = rk4Step<Jet, kN>(xj, s0, s1, wj, dt, gravity);
  x_next->resize(kN);
  dx1_dx0->resize(kN, kN);
  dx1_dw->resize(kN, kW);
  for (int i = 0; i < kN; ++i) {
    (*x_next)(i) = x1(i).a;
    dx1_dx0->row(i) = x1(i).v.template head<kN>().transpose();
    dx1_dw->row(i) = x1(i).v.template tail<kW>().transpose();
  }
}

Status checkInterval(const ImuSample& s0, const ImuSample& s1, double max_dt, double* dt) {
  const int64_t dt_us = s1.t_us - s0.t_us;
  *dt = 1e-6 * static_cast<double>(dt_us);
  if (dt_us <= 0) {
    return Status::Error("IMU timestamps not increasing: " + std::to_string(s0.t_us) + " then " +
                         std::to_string(s1.t_us) + " us");
  }
  if (*dt > max_dt) {
    return Status::Error("IMU gap of " + std::to_string(*dt) + " s exceeds max_dt " +
                         std::to_string(max_dt) + " s");
  }
  return Status::Ok();
}

}  // namespace

ImuSample interpolateImu(const ImuSample& a, const ImuSample& b, int64_t t_us) {
  ImuSample out;
  out.t_us = t_us;
  const int64_t span = b.t_us - a.t_us;
  const double s = span > 0 ? static_cast<double>(t_us - a.t_us) / static_cast<double>(span) : 0.0;
  out.gyro_B = (1.0 - s) * a.gyro_B + s * b.gyro_B;
  out.accel_B = (1.0 - s) * a.accel_B + s * b.accel_B;
  return out;
}

Eigen::VectorXd InsPropagator::noiseVariances(double dt) const {
  Eigen::VectorXd q(noiseSize());
  q.segment<3>(0).setConstant(o_.accel_noise_density * o_.accel_noise_density / dt);
  q.segment<3>(3).setConstant(o_.gyro_noise_density * o_.gyro_noise_density / dt);
  if (o_.estimate_imu_bias) {
    q.segment<3>(6).setConstant(o_.accel_random_walk * o_.accel_random_walk / dt);
    q.segment<3>(9).setConstant(o_.gyro_random_walk * o_.gyro_random_walk / dt);
  }
  return q;
}

Eigen::VectorXd InsPropagator::stepMean(const Eigen::VectorXd& x, const ImuSample& s0,
                                        const ImuSample& s1, const Eigen::VectorXd& w) const {
  const double dt = 1e-6 * static_cast<double>(s1.t_us - s0.t_us);
  if (o_.estimate_imu_bias) {
    return stepMeanFixed<vehicle::kSizeWithBias>(x, s0, s1, w, dt, o_.gravity);
  }
  return stepMeanFixed<vehicle::kSizeNoBias>(x, s0, s1, w, dt, o_.gravity);
}

Status InsPropagator::step(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
                           Eigen::VectorXd* x_next, Eigen::MatrixXd* dx1_dx0,
                           Eigen::MatrixXd* dx1_dw, Eigen::MatrixXd* Q_w) const {
  if (x.size() != stateSize()) {
    return Status::Error("INS state has size " + std::to_string(x.size()) + ", expected " +
                         std::to_string(stateSize()));
  }
  double dt = 0.0;
  if (Status s = checkInterval(s0, s1, o_.max_dt, &dt); !s.ok()) return s;
  // Eq. 2.4 is singular at θ = ±90° (gimbal lock): refuse to step within ~0.06° of it.
  if (std::abs(std::cos(x(vehicle::kAttitude + 1))) < 1e-3) {
    return Status::Error("INS pitch " + std::to_string(x(vehicle::kAttitude + 1)) +
                         " rad is at the Euler singularity (eq. 2.4)");
  }
  if (o_.estimate_imu_bias) {
    stepJacobiansFixed<vehicle::kSizeWithBias>(x, s0, s1, dt, o_.gravity, x_next, dx1_dx0, dx1_dw);
  } else {
    stepJacobiansFixed<vehicle::kSizeNoBias>(x, s0, s1, dt, o_.gravity, x_next, dx1_dx0, dx1_dw);
  }
  // A non-finite step (bad input) must not reach the covariance.
  if (!x_next->allFinite() || !dx1_dx0->allFinite() || !dx1_dw->allFinite()) {
    return Status::Error("INS step is not finite (pitch " +
                         std::to_string(x(vehicle::kAttitude + 1)) +
                         " rad; eq. 2.4 is singular at ±π/2)");
  }
  *Q_w = noiseVariances(dt).asDiagonal();
  return Status::Ok();
}

Status InsPropagator::propagate(const Eigen::VectorXd& x, const std::vector<ImuSample>& samples,
                                InsTransition* out) const {
  if (samples.empty()) return Status::Error("no IMU samples to propagate with");
  const int n = stateSize();
  out->x = x;
  out->Phi.setIdentity(n, n);
  out->Qd.setZero(n, n);
  out->t_us = samples.front().t_us;
  Eigen::VectorXd x_next;
  Eigen::MatrixXd F, G, Q_w;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    if (Status s = step(out->x, samples[k - 1], samples[k], &x_next, &F, &G, &Q_w); !s.ok()) {
      return s;
    }
    out->x = x_next;
    out->Phi = F * out->Phi;
    // Discrete Riccati without measurements (eq. 3.20): Qd ← F Qd Fᵀ + G Q_w Gᵀ.
    out->Qd = F * out->Qd * F.transpose() + G * Q_w * G.transpose();
    out->t_us = samples[k].t_us;
  }
  out->x(vehicle::kAttitude + 2) = wrapAngle(out->x(vehicle::kAttitude + 2));
  return Status::Ok();
}

}  // namespace cvslam
