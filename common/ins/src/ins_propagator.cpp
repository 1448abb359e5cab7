#include "cvslam/ins/ins_propagator.h"

#include <ceres/jet.h>

#include <algorithm>
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
  node.get("noise_density_scale", noise_density_scale);
  node.get("random_walk_scale", random_walk_scale);
  node.get("datasheet_random_walk_scale", datasheet_random_walk_scale);
  node.get("estimate_imu_bias", estimate_imu_bias);
  node.get("gravity", gravity);
  node.get("max_dt", max_dt);
  noise_monitor.load(node);
  std::string attitude_name = attitude == vehicle::Attitude::kEuler ? "euler" : "error_state";
  node.get("attitude", attitude_name);
  node.check(attitude_name == "euler" || attitude_name == "error_state", "attitude",
             "must be error_state or euler");
  attitude = attitude_name == "euler" ? vehicle::Attitude::kEuler : vehicle::Attitude::kErrorState;
  node.check(gyro_noise_density > 0, "gyro_noise_density", "must be > 0");
  node.check(accel_noise_density > 0, "accel_noise_density", "must be > 0");
  node.check(gyro_random_walk > 0, "gyro_random_walk", "must be > 0");
  node.check(accel_random_walk > 0, "accel_random_walk", "must be > 0");
  node.check(noise_density_scale > 0, "noise_density_scale", "must be > 0");
  node.check(random_walk_scale > 0, "random_walk_scale", "must be > 0");
  node.check(datasheet_random_walk_scale > 0, "datasheet_random_walk_scale", "must be > 0");
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
     << "noise_density_scale: " << noise_density_scale << "\n"
     << "random_walk_scale: " << random_walk_scale << "\n"
     << "datasheet_random_walk_scale: " << datasheet_random_walk_scale << "\n"
     << "estimate_imu_bias: " << (estimate_imu_bias ? "true" : "false") << "\n"
     << "gravity: " << gravity << "\n"
     << "max_dt: " << max_dt << "\n"
     << "measure_noise_density: " << (noise_monitor.enabled ? "true" : "false") << "\n"
     << "noise_tau_s: " << noise_monitor.tau_s << "\n"
     << "noise_window_s: " << noise_monitor.window_s << "\n"
     << "attitude: " << (attitude == vehicle::Attitude::kEuler ? "euler" : "error_state") << "\n";
  return os.str();
}

namespace {

/// Classical RK4 from t0 to t0+dt; the IMU input is linear between the samples, so the
/// midpoint stages use the average of the two samples.
template <typename T, int kN>
Eigen::Matrix<T, kN, 1> rk4Step(const Eigen::Matrix<T, kN, 1>& x, const ImuSample& s0,
                                const ImuSample& s1, const Eigen::Matrix<T, kN - 3, 1>& w,
                                double dt, double gravity, const Eigen::Matrix3d* chart) {
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  const Vec3 g0 = s0.gyro_B.cast<T>(), a0 = s0.accel_B.cast<T>();
  const Vec3 g1 = s1.gyro_B.cast<T>(), a1 = s1.accel_B.cast<T>();
  const Vec3 gm = (0.5 * (s0.gyro_B + s1.gyro_B)).cast<T>();
  const Vec3 am = (0.5 * (s0.accel_B + s1.accel_B)).cast<T>();
  const T h(dt), half_h(0.5 * dt);
  using Prop = InsPropagator;
  const auto f = [&](const Eigen::Matrix<T, kN, 1>& xs, const Vec3& gyro, const Vec3& accel) {
    return Prop::dynamics<T, kN>(xs, gyro, accel, w, gravity, chart);
  };
  const Eigen::Matrix<T, kN, 1> k1 = f(x, g0, a0);
  const Eigen::Matrix<T, kN, 1> k2 = f(x + half_h * k1, gm, am);
  const Eigen::Matrix<T, kN, 1> k3 = f(x + half_h * k2, gm, am);
  const Eigen::Matrix<T, kN, 1> k4 = f(x + h * k3, g1, a1);
  return x + (h / T(6.0)) * (k1 + T(2.0) * k2 + T(2.0) * k3 + k4);
}

template <int kN>
Eigen::VectorXd stepMeanFixed(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
                              const Eigen::VectorXd& w, double dt, double gravity,
                              const Eigen::Matrix3d* chart) {
  const Eigen::Matrix<double, kN, 1> xf = x;
  const Eigen::Matrix<double, kN - 3, 1> wf = w;
  return rk4Step<double, kN>(xf, s0, s1, wf, dt, gravity, chart);
}

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  return so3::skew<double>(a);
}

/// The attitude terms of the dynamics, differentiated w.r.t. the attitude entries by a Jet:
/// R_NtoB, the attitude rate and ∂(attitude rate)/∂ω (the latter's value only). Euler:
/// eq. 2.4 (E(φ, θ), singular at θ = ±90°); error state: J_r(δθ)⁻¹ about the chart's R̂.
template <typename Jet>
void attitudeTerms(const Eigen::Vector3d& attitude, const Eigen::Vector3d& omega_B,
                   const Eigen::Matrix3d* chart, Eigen::Matrix<Jet, 3, 3>* R_NtoB,
                   Eigen::Matrix<Jet, 3, 1>* attitude_dot, Eigen::Matrix3d* E) {
  Eigen::Matrix<Jet, 3, 1> a;
  for (int i = 0; i < 3; ++i) a(i) = Jet(attitude(i), i);
  const Eigen::Matrix<Jet, 3, 1> omega_jet = omega_B.cast<Jet>();
  if (chart != nullptr) {
    *R_NtoB = (chart->cast<Jet>() * so3::exp(a)).transpose();
    const Eigen::Matrix<Jet, 3, 3> J_inv = so3::rightJacobianInverse(a);
    *attitude_dot = J_inv * omega_jet;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) (*E)(i, j) = J_inv(i, j).a;
    }
    return;
  }
  *R_NtoB = rotationNavToBody(a);
  *attitude_dot = eulerRates(a, omega_jet);
  // ∂ė/∂ω = E(φ, θ) of eq. 2.4 (ė is linear in ω).
  const double sr = std::sin(attitude(0)), cr = std::cos(attitude(0));
  const double tp = std::tan(attitude(1)), cp = std::cos(attitude(1));
  *E << 1.0, sr * tp, cr * tp, 0.0, cr, -sr, 0.0, sr / cp, cr / cp;
}

/// ẋ = f(x, u, 0) and its Jacobian D = [∂f/∂x | ∂f/∂w]. The attitude-dependent terms (DCM,
/// eq. 2.4 or the chart's) are differentiated with a 3-dimensional Jet on the attitude; the
/// rest is written out (a Jet over all kN + kW inputs costs ~5× more per IMU sample).
template <int kN>
Eigen::Matrix<double, kN, 1> dynamicsWithJacobian(const Eigen::Matrix<double, kN, 1>& x,
                                                  const Eigen::Vector3d& gyro_B,
                                                  const Eigen::Vector3d& accel_B, double gravity,
                                                  const Eigen::Matrix3d* chart,
                                                  Eigen::Matrix<double, kN, 2 * kN - 3>* D) {
  using namespace vehicle;
  using Jet3 = ceres::Jet<double, 3>;
  const Eigen::Vector3d v_B = x.template segment<3>(kVelocity);
  Eigen::Vector3d f_B = accel_B, omega_B = gyro_B;
  if constexpr (kN == kSizeWithBias) {
    f_B -= x.template segment<3>(kAccelBias);
    omega_B -= x.template segment<3>(kGyroBias);
  }
  Eigen::Matrix<Jet3, 3, 3> R_NtoB;
  Eigen::Matrix<Jet3, 3, 1> euler_dot;
  Eigen::Matrix3d E;
  attitudeTerms<Jet3>(x.template segment<3>(kAttitude), omega_B, chart, &R_NtoB, &euler_dot, &E);
  const Eigen::Matrix<Jet3, 3, 1> p_dot = R_NtoB.transpose() * v_B.cast<Jet3>();
  const Eigen::Matrix<Jet3, 3, 1> gravity_B = R_NtoB.col(2) * Jet3(gravity);  // R_NtoB g_N

  Eigen::Matrix<double, kN, 1> xdot = Eigen::Matrix<double, kN, 1>::Zero();
  D->setZero();
  Eigen::Vector3d gravity_value;
  for (int i = 0; i < 3; ++i) {
    xdot(kPosition + i) = p_dot(i).a;
    xdot(kAttitude + i) = euler_dot(i).a;
    gravity_value(i) = gravity_B(i).a;
    D->template block<1, 3>(kPosition + i, kAttitude) = p_dot(i).v.transpose();
    D->template block<1, 3>(kVelocity + i, kAttitude) = gravity_B(i).v.transpose();
    D->template block<1, 3>(kAttitude + i, kAttitude) = euler_dot(i).v.transpose();
    for (int j = 0; j < 3; ++j) (*D)(kPosition + i, kVelocity + j) = R_NtoB(j, i).a;
  }
  xdot.template segment<3>(kVelocity) = f_B + gravity_value - omega_B.cross(v_B);
  // v̇ = f + R g − ω × v: ∂/∂v = −[ω]×, ∂/∂ω = [v]×, and f, ω enter with −b, −n.
  D->template block<3, 3>(kVelocity, kVelocity) = -skew(omega_B);
  const Eigen::Matrix3d dvdot_dgyro = skew(v_B);
  constexpr int kNa = kN, kNg = kN + 3;  // noise columns
  D->template block<3, 3>(kVelocity, kNa) = -Eigen::Matrix3d::Identity();
  D->template block<3, 3>(kVelocity, kNg) = -dvdot_dgyro;
  D->template block<3, 3>(kAttitude, kNg) = -E;
  if constexpr (kN == kSizeWithBias) {
    D->template block<3, 3>(kVelocity, kAccelBias) = -Eigen::Matrix3d::Identity();
    D->template block<3, 3>(kVelocity, kGyroBias) = -dvdot_dgyro;
    D->template block<3, 3>(kAttitude, kGyroBias) = -E;
    D->template block<3, 3>(kAccelBias, kN + 6) = Eigen::Matrix3d::Identity();
    D->template block<3, 3>(kGyroBias, kN + 9) = Eigen::Matrix3d::Identity();
  }
  return xdot;
}

/// RK4 step and its exact Jacobians by the chain rule through the four stages:
/// d(x + c k) = dx + c dk, dk_i = A_i dx_i + B_i dw with x_i the stage point.
template <int kN>
void stepJacobiansFixed(const Eigen::Matrix<double, kN, 1>& x0, const ImuSample& s0,
                        const ImuSample& s1, double dt, double gravity,
                        const Eigen::Matrix3d* chart, Eigen::Matrix<double, kN, 1>* x_next,
                        Eigen::Matrix<double, kN, kN>* dx1_dx0,
                        Eigen::Matrix<double, kN, kN - 3>* dx1_dw) {
  constexpr int kW = kN - 3, kD = kN + kW;
  using Vec = Eigen::Matrix<double, kN, 1>;
  using Jac = Eigen::Matrix<double, kN, kD>;
  const Eigen::Vector3d gm = 0.5 * (s0.gyro_B + s1.gyro_B);
  const Eigen::Vector3d am = 0.5 * (s0.accel_B + s1.accel_B);
  const double h = dt;
  Jac I0 = Jac::Zero();  // d(x)/d[x, w]
  I0.template leftCols<kN>().setIdentity();
  Jac D, dk1, dk2, dk3, dk4;
  const auto stage = [&](const Vec& xs, const Jac& dxs, const Eigen::Vector3d& gyro,
                         const Eigen::Vector3d& accel, Jac* dk) {
    const Vec k = dynamicsWithJacobian<kN>(xs, gyro, accel, gravity, chart, &D);
    // lazyProduct: at 9–15 rows Eigen's GEMM set-up costs more than the arithmetic.
    dk->noalias() = D.template leftCols<kN>().lazyProduct(dxs);
    dk->template rightCols<kW>() += D.template rightCols<kW>();
    return k;
  };
  const Vec k1 = stage(x0, I0, s0.gyro_B, s0.accel_B, &dk1);
  const Vec k2 = stage(x0 + 0.5 * h * k1, I0 + 0.5 * h * dk1, gm, am, &dk2);
  const Vec k3 = stage(x0 + 0.5 * h * k2, I0 + 0.5 * h * dk2, gm, am, &dk3);
  const Vec k4 = stage(x0 + h * k3, I0 + h * dk3, s1.gyro_B, s1.accel_B, &dk4);
  const Jac dx1 = I0 + (h / 6.0) * (dk1 + 2.0 * dk2 + 2.0 * dk3 + dk4);
  *x_next = x0 + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  *dx1_dx0 = dx1.template leftCols<kN>();
  *dx1_dw = dx1.template rightCols<kW>();
}

/// Error state: folds the chart's δθ₁ of x into the nominal q (R̂₁ = R̂ Exp(δθ₁), δθ = 0)
/// and maps the rows of the step's Jacobians into the new error: d(δθ new) = J_r(δθ₁) dδθ₁.
template <int kN, typename MatF, typename MatG>
void foldAttitude(Eigen::Matrix<double, kN, 1>* x, Eigen::Quaterniond* q, MatF* F, MatG* G) {
  const Eigen::Vector3d d = x->template segment<3>(vehicle::kAttitude);
  const Eigen::Matrix3d J_r = so3::rightJacobian<double>(d);
  if (F != nullptr)
    F->template middleRows<3>(vehicle::kAttitude) =
        J_r * F->template middleRows<3>(vehicle::kAttitude);
  if (G != nullptr)
    G->template middleRows<3>(vehicle::kAttitude) =
        J_r * G->template middleRows<3>(vehicle::kAttitude);
  *q = (*q * Eigen::Quaterniond(so3::exp<double>(d))).normalized();
  x->template segment<3>(vehicle::kAttitude).setZero();
}

/// Rejects steps at the Euler singularity and non-finite results.
Status checkStepInput(double pitch) {
  // Eq. 2.4 is singular at θ = ±90° (gimbal lock): refuse to step within ~0.06° of it.
  if (std::abs(std::cos(pitch)) < 1e-3) {
    return Status::Error("INS pitch " + std::to_string(pitch) +
                         " rad is at the Euler singularity (eq. 2.4)");
  }
  return Status::Ok();
}

Status checkStepOutput(bool finite, int64_t t_us) {
  // A non-finite step (bad input) must not reach the covariance.
  if (!finite) {
    return Status::Error("INS step is not finite (check the IMU sample at " + std::to_string(t_us) +
                         " us)");
  }
  return Status::Ok();
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

template <int kN>
void stepDynamic(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1, double dt,
                 double gravity, Eigen::Quaterniond* q, Eigen::VectorXd* x_next,
                 Eigen::MatrixXd* dx1_dx0, Eigen::MatrixXd* dx1_dw) {
  Eigen::Matrix<double, kN, 1> x1;
  Eigen::Matrix<double, kN, kN> F;
  Eigen::Matrix<double, kN, kN - 3> G;
  const Eigen::Matrix3d R0 = q != nullptr ? q->toRotationMatrix() : Eigen::Matrix3d::Identity();
  stepJacobiansFixed<kN>(x, s0, s1, dt, gravity, q != nullptr ? &R0 : nullptr, &x1, &F, &G);
  if (q != nullptr) foldAttitude<kN>(&x1, q, &F, &G);
  *x_next = x1;
  *dx1_dx0 = F;
  *dx1_dw = G;
}

/// propagate() with fixed-size matrices: dynamic 9×9 products spent more time in GEMM set-up
/// than in the model. q: the nominal rotation (error state), null for Euler angles.
template <int kN>
Status propagateFixed(const InsPropagator& ins, const Eigen::VectorXd& x, Eigen::Quaterniond* q,
                      const std::vector<ImuSample>& samples, InsTransition* out) {
  using Mat = Eigen::Matrix<double, kN, kN>;
  Eigen::Matrix<double, kN, 1> xk = x, x_next;
  Mat Phi = Mat::Identity(), Qd = Mat::Zero(), F;
  Eigen::Matrix<double, kN, kN - 3> G;
  Eigen::Matrix3d R0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    double dt = 0.0;
    const ImuSample &s0 = samples[k - 1], &s1 = samples[k];
    if (Status s = checkInterval(s0, s1, ins.options().max_dt, &dt); !s.ok()) return s;
    if (q == nullptr) {
      if (Status s = checkStepInput(xk(vehicle::kAttitude + 1)); !s.ok()) return s;
    } else {
      R0 = q->toRotationMatrix();
    }
    stepJacobiansFixed<kN>(xk, s0, s1, dt, ins.options().gravity, q != nullptr ? &R0 : nullptr,
                           &x_next, &F, &G);
    const bool finite = x_next.allFinite() && F.allFinite() && G.allFinite();
    if (Status s = checkStepOutput(finite, s1.t_us); !s.ok()) return s;
    if (q != nullptr) foldAttitude<kN>(&x_next, q, &F, &G);
    const Eigen::Matrix<double, kN - 3, 1> qw = ins.noiseVariances(dt);
    xk = x_next;
    Phi = F.lazyProduct(Phi).eval();
    // Discrete Riccati without measurements (eq. 3.20): Qd ← F Qd Fᵀ + G Q_w Gᵀ.
    const Mat FQd = F.lazyProduct(Qd);
    const Eigen::Matrix<double, kN, kN - 3> GQ = G * qw.asDiagonal();
    Qd = FQd.lazyProduct(F.transpose()) + GQ.lazyProduct(G.transpose());
  }
  out->x = xk;
  out->Phi = Phi;
  out->Qd = Qd;
  out->t_us = samples.back().t_us;
  if (q != nullptr) out->q_BtoN = *q;
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

double InsPropagator::gyroNoiseDensity() const {
  return std::max(o_.noise_density_scale * o_.gyro_noise_density, measured_gyro_density_);
}

double InsPropagator::accelNoiseDensity() const {
  return std::max(o_.noise_density_scale * o_.accel_noise_density, measured_accel_density_);
}

Eigen::VectorXd InsPropagator::noiseVariances(double dt) const {
  Eigen::VectorXd q(noiseSize());
  const double white = o_.noise_density_scale * o_.noise_density_scale / dt;
  const double walk_scale = o_.random_walk_scale * o_.datasheet_random_walk_scale;
  const double walk = walk_scale * walk_scale / dt;
  // The configured term as it always was (bit for bit) unless the measured one is larger.
  const auto variance = [&](double density, double measured) {
    const double configured = density * density * white;
    const double in_flight = measured * measured / dt;
    return in_flight > configured ? in_flight : configured;
  };
  q.segment<3>(0).setConstant(variance(o_.accel_noise_density, measured_accel_density_));
  q.segment<3>(3).setConstant(variance(o_.gyro_noise_density, measured_gyro_density_));
  if (o_.estimate_imu_bias) {
    q.segment<3>(6).setConstant(o_.accel_random_walk * o_.accel_random_walk * walk);
    q.segment<3>(9).setConstant(o_.gyro_random_walk * o_.gyro_random_walk * walk);
  }
  return q;
}

Eigen::VectorXd InsPropagator::stepMean(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN,
                                        const ImuSample& s0, const ImuSample& s1,
                                        const Eigen::VectorXd& w,
                                        Eigen::Quaterniond* q_next) const {
  const double dt = 1e-6 * static_cast<double>(s1.t_us - s0.t_us);
  const bool euler = o_.attitude == vehicle::Attitude::kEuler;
  const Eigen::Matrix3d R0 = q_BtoN.toRotationMatrix();
  const Eigen::Matrix3d* chart = euler ? nullptr : &R0;
  Eigen::VectorXd x1 =
      o_.estimate_imu_bias
          ? stepMeanFixed<vehicle::kSizeWithBias>(x, s0, s1, w, dt, o_.gravity, chart)
          : stepMeanFixed<vehicle::kSizeNoBias>(x, s0, s1, w, dt, o_.gravity, chart);
  if (euler) {
    if (q_next != nullptr) *q_next = q_BtoN;
    return x1;
  }
  const Eigen::Vector3d d = x1.segment<3>(vehicle::kAttitude);
  *q_next = (q_BtoN * Eigen::Quaterniond(so3::exp<double>(d))).normalized();
  x1.segment<3>(vehicle::kAttitude).setZero();
  return x1;
}

void InsPropagator::fromEulerLayout(const Eigen::VectorXd& x_euler, Eigen::VectorXd* x,
                                    Eigen::Quaterniond* q_BtoN) const {
  *x = x_euler;
  *q_BtoN = Eigen::Quaterniond::Identity();
  if (o_.attitude == vehicle::Attitude::kEuler) return;
  const Eigen::Vector3d e = x_euler.segment<3>(vehicle::kAttitude);
  *q_BtoN = Eigen::Quaterniond(rotationBodyToNav(e)).normalized();
  x->segment<3>(vehicle::kAttitude).setZero();
}

Eigen::VectorXd InsPropagator::eulerLayout(const Eigen::VectorXd& x,
                                           const Eigen::Quaterniond& q_BtoN) const {
  if (o_.attitude == vehicle::Attitude::kEuler) return x;
  Eigen::VectorXd out = x;
  const Eigen::Matrix3d R_BtoN =
      q_BtoN.toRotationMatrix() * so3::exp<double>(x.segment<3>(vehicle::kAttitude));
  out.segment<3>(vehicle::kAttitude) = eulerFromRotationNavToBody(R_BtoN.transpose());
  return out;
}

Eigen::VectorXd InsPropagator::stepMean(const Eigen::VectorXd& x, const ImuSample& s0,
                                        const ImuSample& s1, const Eigen::VectorXd& w) const {
  return stepMean(x, Eigen::Quaterniond::Identity(), s0, s1, w, nullptr);
}

Status InsPropagator::step(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN,
                           const ImuSample& s0, const ImuSample& s1, Eigen::VectorXd* x_next,
                           Eigen::Quaterniond* q_next, Eigen::MatrixXd* dx1_dx0,
                           Eigen::MatrixXd* dx1_dw, Eigen::MatrixXd* Q_w) const {
  if (x.size() != stateSize()) {
    return Status::Error("INS state has size " + std::to_string(x.size()) + ", expected " +
                         std::to_string(stateSize()));
  }
  double dt = 0.0;
  if (Status s = checkInterval(s0, s1, o_.max_dt, &dt); !s.ok()) return s;
  const bool euler = o_.attitude == vehicle::Attitude::kEuler;
  if (euler) {
    if (Status s = checkStepInput(x(vehicle::kAttitude + 1)); !s.ok()) return s;
  }
  Eigen::Quaterniond q = q_BtoN;
  Eigen::Quaterniond* nominal = euler ? nullptr : &q;
  if (o_.estimate_imu_bias) {
    stepDynamic<vehicle::kSizeWithBias>(x, s0, s1, dt, o_.gravity, nominal, x_next, dx1_dx0,
                                        dx1_dw);
  } else {
    stepDynamic<vehicle::kSizeNoBias>(x, s0, s1, dt, o_.gravity, nominal, x_next, dx1_dx0, dx1_dw);
  }
  const bool finite = x_next->allFinite() && dx1_dx0->allFinite() && dx1_dw->allFinite();
  if (Status s = checkStepOutput(finite, s1.t_us); !s.ok()) return s;
  if (q_next != nullptr) *q_next = q;
  *Q_w = noiseVariances(dt).asDiagonal();
  return Status::Ok();
}

Status InsPropagator::step(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
                           Eigen::VectorXd* x_next, Eigen::MatrixXd* dx1_dx0,
                           Eigen::MatrixXd* dx1_dw, Eigen::MatrixXd* Q_w) const {
  if (o_.attitude != vehicle::Attitude::kEuler) {
    return Status::Error("InsPropagator::step without a nominal rotation needs attitude: euler");
  }
  return step(x, Eigen::Quaterniond::Identity(), s0, s1, x_next, nullptr, dx1_dx0, dx1_dw, Q_w);
}

Status InsPropagator::propagate(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN,
                                const std::vector<ImuSample>& samples, InsTransition* out) const {
  if (samples.empty()) return Status::Error("no IMU samples to propagate with");
  if (x.size() != stateSize()) {
    return Status::Error("INS state has size " + std::to_string(x.size()) + ", expected " +
                         std::to_string(stateSize()));
  }
  const bool euler = o_.attitude == vehicle::Attitude::kEuler;
  Eigen::Quaterniond q = q_BtoN.normalized();
  Eigen::Quaterniond* nominal = euler ? nullptr : &q;
  const Status s = o_.estimate_imu_bias
                       ? propagateFixed<vehicle::kSizeWithBias>(*this, x, nominal, samples, out)
                       : propagateFixed<vehicle::kSizeNoBias>(*this, x, nominal, samples, out);
  if (!s.ok()) return s;
  if (euler) out->x(vehicle::kAttitude + 2) = wrapAngle(out->x(vehicle::kAttitude + 2));
  return Status::Ok();
}

Status InsPropagator::propagate(const Eigen::VectorXd& x, const std::vector<ImuSample>& samples,
                                InsTransition* out) const {
  if (o_.attitude != vehicle::Attitude::kEuler) {
    return Status::Error(
        "InsPropagator::propagate without a nominal rotation needs attitude: euler");
  }
  return propagate(x, Eigen::Quaterniond::Identity(), samples, out);
}

}  // namespace cvslam
