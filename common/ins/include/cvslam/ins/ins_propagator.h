#pragma once
// Strap-down INS process model (thesis §2.3.2, §5.3; docs/conventions.md) and its discretisation.
//
// State x_v = [p_BinN | v_B | attitude | (b_a | b_g)], see vehicle_state_layout.h.
// Noise  w  = [n_a | n_g | (n_ba | n_bg)] (same order as the state it drives).
// Continuous dynamics, with ω = gyro − b_g − n_g and f = accel − b_a − n_a:
//   ṗ_N = R_BtoN v_B                          (eq. 2.7)
//   v̇_B = f + R_NtoB g_N − ω × v_B            (eq. 2.5 with the sign fixed by docs/conventions.md)
//   ė   = E(φ, θ) ω                           (eq. 2.4; `attitude: euler`)
//   δθ̇  = J_r(δθ)⁻¹ ω,  R_BtoN = R̂ Exp(δθ)    (`attitude: error_state`, so3.h)
//   ḃ_a = n_ba,  ḃ_g = n_bg                   (random walks, beyond the thesis)
// Error state (`attitude: error_state`, docs/filter.md): each step integrates in the chart around
// the nominal R̂ at its start (the rotation written as δθ, RK4 on the chart, which is the
// quaternion's RK4 up to the chart's own terms), then folds δθ₁ into the nominal,
// R̂₁ = R̂ Exp(δθ₁), δθ = 0. F and G are the exact Jacobians of that map in the error
// coordinates, x₀⊞δ ↦ step(x₀⊞δ)⊟step(x₀): the chart step's, times J_r(δθ₁) on the attitude
// rows for the fold. No singularity at any attitude.
// Discretisation per IMU interval [t0, t1]: classical RK4 on the mean with the IMU input
// interpolated linearly between the two samples and the noise held constant over the step
// (zero-order hold). The discrete white noise then has covariance Q_w = diag(σ²/dt) for a
// continuous density σ, which makes the discrete covariance P ← F P Fᵀ + G Q_w Gᵀ exact to
// first order. F = ∂x₁/∂x₀ and G = ∂x₁/∂w are the exact Jacobians of the RK4 map itself
// (chain rule through the four stages; stage Jacobians written out, with the attitude terms
// differentiated by a 3-dimensional ceres::Jet), so they agree with the mean propagation
// rather than with an Euler approximation of it.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/imu_noise_monitor.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

class ConfigNode;

struct InsPropagatorOptions {
  /// σ_g, gyro white-noise density [rad/s/√Hz] (EuRoC ADIS16448: 1.6968e-4).
  double gyro_noise_density = 1.6968e-4;
  /// σ_a, accelerometer white-noise density [m/s²/√Hz] (EuRoC: 2.0e-3).
  double accel_noise_density = 2.0e-3;
  /// σ_bg, gyro bias random walk [rad/s²/√Hz] (EuRoC: 1.9393e-5).
  double gyro_random_walk = 1.9393e-5;
  /// σ_ba, accelerometer bias random walk [m/s³/√Hz] (EuRoC: 3.0e-3).
  double accel_random_walk = 3.0e-3;
  /// Factors on the four densities above, whatever set them (this file, the simulated IMU or a
  /// recording's imu0/sensor.yaml): the datasheet describes an IMU at rest, a flying one sees
  /// vibration, temperature and scale errors the model lacks (docs/results/euroc_recorded.md:
  /// the real V1_02 IMU's 1 s means stray 19× (accelerometer) and 8× (gyro) farther from
  /// the truth than its white-noise density allows).
  double noise_density_scale = 1.0;  ///< on σ_g and σ_a
  double random_walk_scale = 1.0;    ///< on σ_bg and σ_ba
  /// A further factor on σ_bg and σ_ba while they are a datasheet's (this file, a recording's
  /// imu0/sensor.yaml, a real IMU recording played in a scenario). The simulator's IMU has no
  /// datasheet: simulatedAgentSetup gives the filter its true densities and sets this to 1.
  /// 3: most of what larger factors gain on euroc_mh03_hall's real-IMU UAV over seeds 301–320
  /// (docs/results/euroc_recorded.md "Datasheet random walks").
  double datasheet_random_walk_scale = 3.0;
  /// The white-noise densities measured in flight (imu_noise_monitor.h; keys
  /// measure_noise_density, noise_tau_s, noise_window_s): the filter assumes the larger of
  /// them and the scaled densities above. Off for a simulated IMU, whose densities are true.
  ImuNoiseMonitorOptions noise_monitor;
  /// Adds b_a and b_g (6 states) to the vehicle state.
  bool estimate_imu_bias = false;
  /// |g_N| [m/s²]; g_N = [0 0 gravity] in NED.
  double gravity = 9.81;
  /// IMU intervals longer than this are rejected as a data gap [s].
  double max_dt = 0.1;
  /// How the attitude is estimated (`attitude: error_state | euler`): a rotation error state
  /// about a nominal rotation (no singularity, any IMU mounting), or the thesis's ZYX Euler
  /// angles (singular at pitch ±90°). Default error_state since the invariant error chart,
  /// where the two are equally accurate on the scenarios and the error state is the more
  /// accurate on the recordings (docs/filter.md "Attitude"); the ground station keeps euler.
  vehicle::Attitude attitude = vehicle::Attitude::kErrorState;

  Status load(const ConfigNode& node);
  /// The options as YAML (one `key: value` per line); load() reads it back unchanged.
  std::string print() const;
};

/// Result of propagating the vehicle state over several IMU intervals.
struct InsTransition {
  Eigen::VectorXd x;    ///< vehicle state at the last sample
  Eigen::MatrixXd Phi;  ///< ∂x_end/∂x_start (product of the per-step F)
  Eigen::MatrixXd Qd;   ///< accumulated process noise Σ Φ(end,k) G_k Q_k G_kᵀ Φ(end,k)ᵀ
  int64_t t_us = 0;     ///< time of x
  /// error_state: the nominal rotation R̂ (body to N) at t_us; x's δθ is then zero.
  Eigen::Quaterniond q_BtoN = Eigen::Quaterniond::Identity();
};

/// IMU sample at t_us by linear interpolation between a and b (a.t_us ≤ t_us ≤ b.t_us), to
/// end a propagation exactly at a camera timestamp (same input model as the RK4 step).
ImuSample interpolateImu(const ImuSample& a, const ImuSample& b, int64_t t_us);

class InsPropagator {
 public:
  explicit InsPropagator(const InsPropagatorOptions& options = {}) : o_(options) {}
  const InsPropagatorOptions& options() const { return o_; }

  int stateSize() const { return vehicle::size(o_.estimate_imu_bias); }
  int noiseSize() const { return stateSize() - 3; }

  /// Diagonal of Q_w for an interval dt: σ²/dt for each noise (zero-order-hold white noise).
  /// The white noises' σ is max(noise_density_scale × density, the measured density).
  Eigen::VectorXd noiseVariances(double dt) const;

  /// Densities measured in flight (ImuNoiseMonitor) [rad/s/√Hz], [m/s²/√Hz]; 0: none.
  void setMeasuredNoiseDensities(double gyro, double accel) {
    measured_gyro_density_ = gyro;
    measured_accel_density_ = accel;
  }
  double gyroNoiseDensity() const;   ///< σ_g the model uses
  double accelNoiseDensity() const;  ///< σ_a the model uses

  /// Mean of one RK4 step from s0 to s1 with the noise w held over the step (w may be zero).
  /// x's attitude is read per options().attitude; error_state: about the nominal q_BtoN, and
  /// the result's δθ is folded into *q_next (zero in the result). q_next may be null in Euler
  /// mode. No dt check: callers that take data from outside use step() or propagate().
  Eigen::VectorXd stepMean(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN,
                           const ImuSample& s0, const ImuSample& s1, const Eigen::VectorXd& w,
                           Eigen::Quaterniond* q_next) const;

  /// One step with Jacobians dx1_dx0 (F) and dx1_dw (G) and the noise covariance Q_w, in the
  /// error coordinates (error_state: q_BtoN is the nominal, *q_next the new one).
  /// Rejects dt ≤ 0 and dt > max_dt.
  Status step(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN, const ImuSample& s0,
              const ImuSample& s1, Eigen::VectorXd* x_next, Eigen::Quaterniond* q_next,
              Eigen::MatrixXd* dx1_dx0, Eigen::MatrixXd* dx1_dw, Eigen::MatrixXd* Q_w) const;

  /// Propagates x (valid at samples.front().t_us; error_state: about the nominal q_BtoN)
  /// through every consecutive pair of samples. Euler: the yaw of the result is wrapped to
  /// (−π, π]; error_state: the result's δθ is zero and out->q_BtoN the nominal.
  Status propagate(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN,
                   const std::vector<ImuSample>& samples, InsTransition* out) const;

  /// A state in the Euler layout [p, v_B, φ θ ψ, (b)] as this propagator's (x, nominal):
  /// error_state: R̂ = R(φ θ ψ), δθ = 0; Euler: unchanged (q = identity).
  void fromEulerLayout(const Eigen::VectorXd& x_euler, Eigen::VectorXd* x,
                       Eigen::Quaterniond* q_BtoN) const;
  /// The inverse (error_state: φ θ ψ of R̂ Exp(δθ)), for outputs people read.
  Eigen::VectorXd eulerLayout(const Eigen::VectorXd& x, const Eigen::Quaterniond& q_BtoN) const;

  /// The three above for the Euler attitude (options().attitude must be euler).
  Eigen::VectorXd stepMean(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
                           const Eigen::VectorXd& w) const;
  Status step(const Eigen::VectorXd& x, const ImuSample& s0, const ImuSample& s1,
              Eigen::VectorXd* x_next, Eigen::MatrixXd* dx1_dx0, Eigen::MatrixXd* dx1_dw,
              Eigen::MatrixXd* Q_w) const;
  Status propagate(const Eigen::VectorXd& x, const std::vector<ImuSample>& samples,
                   InsTransition* out) const;

  /// Continuous dynamics ẋ = f(x, u, w), templated so that ceres::Jet can differentiate it.
  /// `chart`: null for the Euler attitude, else the nominal R̂ (body to N) of the δθ chart.
  template <typename T, int kN>
  static Eigen::Matrix<T, kN, 1> dynamics(const Eigen::Matrix<T, kN, 1>& x,
                                          const Eigen::Matrix<T, 3, 1>& gyro_B,
                                          const Eigen::Matrix<T, 3, 1>& accel_B,
                                          const Eigen::Matrix<T, kN - 3, 1>& w, double gravity,
                                          const Eigen::Matrix3d* chart = nullptr);

 private:
  InsPropagatorOptions o_;
  double measured_gyro_density_ = 0.0;
  double measured_accel_density_ = 0.0;
};

// ---- template implementation ----------------------------------------------------------

template <typename T, int kN>
Eigen::Matrix<T, kN, 1> InsPropagator::dynamics(const Eigen::Matrix<T, kN, 1>& x,
                                                const Eigen::Matrix<T, 3, 1>& gyro_B,
                                                const Eigen::Matrix<T, 3, 1>& accel_B,
                                                const Eigen::Matrix<T, kN - 3, 1>& w,
                                                double gravity, const Eigen::Matrix3d* chart) {
  static_assert(kN == vehicle::kSizeNoBias || kN == vehicle::kSizeWithBias);
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  const Vec3 v_B = x.template segment<3>(vehicle::kVelocity);
  const Vec3 attitude = x.template segment<3>(vehicle::kAttitude);
  Vec3 f_B = accel_B - w.template segment<3>(0);
  Vec3 omega_B = gyro_B - w.template segment<3>(3);
  if constexpr (kN == vehicle::kSizeWithBias) {
    f_B -= x.template segment<3>(vehicle::kAccelBias);
    omega_B -= x.template segment<3>(vehicle::kGyroBias);
  }
  const Eigen::Matrix<T, 3, 3> R_NtoB =
      chart == nullptr
          ? rotationNavToBody(attitude)
          : Eigen::Matrix<T, 3, 3>((chart->cast<T>() * so3::exp(attitude)).transpose());
  const Vec3 g_N(T(0.0), T(0.0), T(gravity));

  Eigen::Matrix<T, kN, 1> xdot;
  xdot.template segment<3>(vehicle::kPosition) = R_NtoB.transpose() * v_B;
  xdot.template segment<3>(vehicle::kVelocity) = f_B + R_NtoB * g_N - omega_B.cross(v_B);
  xdot.template segment<3>(vehicle::kAttitude) =
      chart == nullptr ? eulerRates(attitude, omega_B)
                       : Vec3(so3::rightJacobianInverse(attitude) * omega_B);
  if constexpr (kN == vehicle::kSizeWithBias) {
    xdot.template segment<3>(vehicle::kAccelBias) = w.template segment<3>(6);
    xdot.template segment<3>(vehicle::kGyroBias) = w.template segment<3>(9);
  }
  return xdot;
}

}  // namespace cvslam
