#pragma once
// State-dependent Riccati equation (SDRE) nonlinear filter for GPS-aided INS (thesis §3.5.3,
// eqs. 3.26–3.28; Cloutier et al.).
//
// Between fixes the estimate follows the full nonlinear mechanisation, x̂̇ = f(x̂, u) =
// A(x̂, u) x̂ + b(u) (the SDC form, sdc_factorisation.h; the same RK4 step as the other
// filters, so no filter gains accuracy from a different integrator). At each fix (the
// thesis's filter rate) the gain of eq. 3.27 is computed from the *steady-state* Riccati
// solution of the frozen SDC pair (A(x̂), H(x̂)) — no Jacobian, no covariance recursion:
//   Φ = ρ · exp(A(x̂) T)   over the time T since the previous fix,
//   Q = Σ Γ(x̂) Q_c Γ(x̂)ᵀ dt accumulated over the IMU steps since the previous fix,
//   P = DARE(Φ, H(x̂), R, Q)  (riccati.h: the discrete form of eq. 3.28, since fixes are
//       discrete; the continuous ARE with T → 0 is the same steady state in the limit),
//   K = P Hᵀ (H P Hᵀ + R)⁻¹,  x̂ ← x̂ + K (y − h(x̂))   (eqs. 3.26–3.27; h(x̂) = H(x̂) x̂).
// ρ ≤ 1 (`riccati_discount`) makes marginal modes that the frozen pair cannot see (yaw in
// straight, unaccelerated flight) slightly stable, so the DARE always has a finite solution;
// ρ = 1 is the thesis's filter exactly.
// covariance() is the posterior P(I − KH)-form of the last fix plus the noise accumulated
// since; it is what NEES is computed against.

#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_filter.h"
#include "cvslam/insgps/riccati.h"
#include "cvslam/insgps/sdc_factorisation.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::insgps {

struct SdreOptions {
  /// α of F(x, α) = α F₁ + (1 − α) F₂ (thesis §3.7.1; 0.5 in §3.7.2.1).
  double alpha = 0.5;
  /// ρ ∈ (0, 1]: discount of the frozen transition Φ per fix (see above).
  double riccati_discount = 0.999;
  /// Multiplies Q in the Riccati equation (a design weight of eq. 3.28, ≥ 1): the steady-state
  /// gain of the frozen pair ignores that A(x̂) changes from fix to fix, which a larger Q
  /// stands for. 1: the IMU noise alone; 100 (default) measured best on
  /// config/ins_gps/sharp_manoeuvres.yaml (docs/results/thesis_ch3.md).
  double process_noise_scale = 100.0;
  RiccatiOptions riccati;
  SdcOptions sdc;

  Status load(const ConfigNode& node);
};

class SdreFilter : public GpsAidedFilter {
 public:
  SdreFilter(const InsPropagatorOptions& ins, const SdreOptions& options = {});
  std::string name() const override { return "sdre"; }
  void initialize(const StateVector& x0, const StateMatrix& P0, int64_t t_us) override;
  Status propagate(const ImuSample& s0, const ImuSample& s1) override;
  Status update(const GpsFix& fix) override;
  StateVector state() const override { return x_; }
  StateMatrix covariance() const override { return P_post_ + Q_acc_; }
  /// Doubling steps of the last Riccati solve.
  int lastRiccatiIterations() const { return riccati_iterations_; }

 private:
  InsPropagator propagator_;
  SdreOptions o_;
  StateVector x_ = StateVector::Zero();
  StateMatrix P_post_ = StateMatrix::Identity();
  StateMatrix Q_acc_ = StateMatrix::Zero();
  double T_ = 0.0;  // time since the last fix [s]
  ImuSample last_imu_;
  bool have_imu_ = false;
  int riccati_iterations_ = 0;
};

}  // namespace cvslam::insgps
