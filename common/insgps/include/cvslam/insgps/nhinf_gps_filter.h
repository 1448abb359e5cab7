#pragma once
// Nonlinear H∞ filter (NH∞) for GPS-aided INS (thesis §3.6.5, after Einicke & White 1999).
//
// An extended H∞ filter (EKF structure, §3.6.4) on the scaled problem of eqs. 3.57–3.58:
// the linearisation remainders Π, Σ (eqs. 3.53–3.56, norm bounds δ₁ δ₂ δ₃) are absorbed by
// scaling the noises with
//   c_v² = 1 − γ⁻²(δ₁² + δ₃²),   c_w² = c_v² / (1 + δ₂²)
// (the thesis prints γ² where the H∞ level enters as 1/γ² = θ, eq. 3.50; with γ² the bound
// would fail for any γ > 1/δ; checked by the test that γ → ∞ gives the EKF). The filter is
// designed for the model with noises w/c_w and v/c_v, i.e. Q/c_w², R/c_v² (inflated: the
// remainders are extra disturbance).
// Correction (eqs. 3.39–3.40 with L = S = I, θ = 1/γ², in information form):
//   P⁺ = (P⁻¹ − θ I + Hᵀ R⁻¹ H)⁻¹,   K = P⁺ Hᵀ R⁻¹,   x̂ ← x̂ + K (y − h(x̂))
// which equals the block form of eqs. 3.49–3.50 with C = I (test; the thesis's −C signs
// cancel, as do the [Cᵀ Hᵀ] ones used in hinfPosteriorBlockForm). The existence condition (3.40),
// P⁻¹ − θ I + Hᵀ R⁻¹ H > 0, is checked at each fix; when it fails θ is lowered to
// `theta_backoff` × its limit for that fix (the thesis's "search over γ"), and counted.

#include "cvslam/insgps/gps_aided_ekf.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::insgps {

struct NhinfOptions {
  double gamma = 10.0;         ///< H∞ performance level γ (θ = 1/γ²; ∞: the EKF)
  double delta1 = 0.02;        ///< bound on the state remainder Δ₁ (eq. 3.55)
  double delta2 = 0.02;        ///< bound on the noise-coupled remainder Δ₂ (eq. 3.55)
  double delta3 = 0.02;        ///< bound on the observation remainder Δ₃ (eq. 3.56)
  double theta_backoff = 0.5;  ///< θ ← backoff · λ_min(P⁻¹ + HᵀR⁻¹H) when (3.40) fails

  Status load(const ConfigNode& node);
  double cv2() const { return 1.0 - (delta1 * delta1 + delta3 * delta3) / (gamma * gamma); }
  double cw2() const { return cv2() / (1.0 + delta2 * delta2); }
};

/// The H∞ a-posteriori covariance of eqs. 3.49–3.50 (block form, C = I), for tests.
StateMatrix hinfPosteriorBlockForm(const StateMatrix& P, const MeasJacobian& H, const MeasMatrix& R,
                                   double theta);

class NhinfGpsFilter : public GpsAidedEkf {
 public:
  NhinfGpsFilter(const InsPropagatorOptions& ins, const NhinfOptions& options = {});
  std::string name() const override { return "nhinf"; }
  Status propagate(const ImuSample& s0, const ImuSample& s1) override;
  Status update(const GpsFix& fix) override;
  /// Fixes at which condition 3.40 failed and θ was lowered.
  int thetaBackoffs() const { return backoffs_; }

 private:
  NhinfOptions ho_;
  int backoffs_ = 0;
};

}  // namespace cvslam::insgps
