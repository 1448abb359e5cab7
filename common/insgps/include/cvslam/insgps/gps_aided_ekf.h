#pragma once
// Extended Kalman filter for GPS-aided INS (thesis §3.4, eqs. 3.19–3.23).
//
// Prediction per IMU interval by the shared RK4 mechanisation (ins_propagator.h), whose exact
// Jacobians give F = ∂x₁/∂x₀ and Γ = ∂x₁/∂w (eq. 3.20): P ← F P Fᵀ + Γ Q_w Γᵀ.
// Correction at each fix, linearised at the prediction: H = ∂h/∂x (gps_measurement.h),
// K = P Hᵀ (H P Hᵀ + R)⁻¹ (eq. 3.22; the thesis's "P H" lacks the transpose), and the
// Joseph form of eq. 3.23 (symmetric, positive definite whatever K).

#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_filter.h"
#include "cvslam/insgps/kalman_correction.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::insgps {

struct EkfOptions {
  /// Joseph form (eq. 3.23, second form) instead of P − K H P (first form).
  bool joseph_form = true;
  /// Rejects a fix whose innovation's squared Mahalanobis distance exceeds this (χ²₆
  /// quantile; 0: no gate). Guards against GPS outliers (heavy-tailed errors, §2.4).
  double innovation_gate = 0.0;

  Status load(const ConfigNode& node);
};

class GpsAidedEkf : public GpsAidedFilter {
 public:
  GpsAidedEkf(const InsPropagatorOptions& ins, const EkfOptions& options = {});
  std::string name() const override { return "ekf"; }
  void initialize(const StateVector& x0, const StateMatrix& P0, int64_t t_us) override;
  Status propagate(const ImuSample& s0, const ImuSample& s1) override;
  Status update(const GpsFix& fix) override;
  StateVector state() const override { return x_; }
  StateMatrix covariance() const override { return P_; }
  /// Fixes rejected by the innovation gate so far.
  int rejectedFixes() const { return rejected_; }

 protected:
  /// Prediction with the process noise scaled by noise_scale (NH∞ inflates it).
  Status predict(const ImuSample& s0, const ImuSample& s1, double noise_scale);

  InsPropagator propagator_;
  EkfOptions o_;
  StateVector x_ = StateVector::Zero();
  StateMatrix P_ = StateMatrix::Identity();
  int rejected_ = 0;
};

}  // namespace cvslam::insgps
