#pragma once
// What makes an EKF and a nonlinear H∞ filter different (thesis §3.4, §3.6.5; docs/conventions.md):
// only the numbers in an UpdatePolicy. CovarianceHelper applies the policy to any stacked
// state, so the agents' filters and the ground station's joint filter share one code path.
//
// NH∞ (Einicke & White's scaled problem, eqs. 3.57–3.58):
//   c_v² = 1 − γ² δ1² − γ² δ3²,  c_w² = c_v² / (1 + δ2²),  θ = 1/γ²
//   prediction   P⁻ = F P Fᵀ + c_w² G Q Gᵀ
//   gain         K  = P⁻ Hᵀ (H P⁻ Hᵀ + c_v² R)⁻¹             (from the H∞ prior, eq. 3.48)
//   posterior    P⁺ = (P⁻⁻¹ + Hᵀ (c_v² R)⁻¹ H − θ I)⁻¹        (eq. 3.39 with S = I)
// which must be positive definite (eq. 3.40). With θ = 0 and δ = 0 this is the EKF.

#include <string>

#include "cvslam/core/status.h"

namespace cvslam {

class ConfigNode;

/// Where the NH∞ term θ S of eq. 3.39 acts.
enum class ThetaWeighting {
  /// S = I, as docs/conventions.md writes it: every state direction is inflated. In SLAM the gauge
  /// directions (common shift/yaw of vehicle and map) get no information from any update,
  /// so their variance grows without bound (a Riccati blow-up) for any fixed θ > 0.
  kIdentity,
  /// S = Π, the projector onto the directions the update observes (range of Hᵀ): the H∞
  /// robustness acts where measurements act, and unobservable directions keep the EKF's
  /// covariance. The default for the SLAM filters.
  kObserved,
};

/// The numbers CovarianceHelper needs to run an EKF or an NH∞ update.
struct UpdatePolicy {
  double theta = 0.0;                    ///< θ = 1/γ²; 0 gives the EKF (Joseph form)
  double measurement_noise_scale = 1.0;  ///< c_v² (multiplies R)
  double process_noise_scale = 1.0;      ///< c_w² (multiplies the process noise)
  /// Largest admissible θ·λ_max(P_EKF⁺). 1 is the bare eq. 3.40 condition; below 1 it
  /// bounds the inflation of P⁺ over the EKF posterior by 1/(1 − margin).
  double theta_margin = 0.9;
  /// Mahalanobis gate per observation: reject when d² > χ²_rows(gate_probability).
  /// 0 disables gating.
  double gate_probability = 0.0;
  /// Where θ acts (see ThetaWeighting).
  ThetaWeighting theta_weighting = ThetaWeighting::kObserved;

  static UpdatePolicy ekf(double gate_probability = 0.0);
};

enum class FilterType { kEkf, kNhinf };

/// Filter options (config section `filter:`).
struct FilterOptions {
  FilterType type = FilterType::kEkf;  ///< `ekf` or `nhinf`
  /// γ of the NH∞ filter, θ = 1/γ² [1/(state unit)]; must exceed the largest standard
  /// deviation of the posterior for eq. 3.40 to hold without fallback.
  double gamma = 10.0;
  double delta1 = 0.0;        ///< δ1, bound on the process-model linearisation error (eq. 3.55)
  double delta2 = 0.0;        ///< δ2, bound on the noise-coupling linearisation error (eq. 3.55)
  double delta3 = 0.0;        ///< δ3, bound on the observation linearisation error (eq. 3.56)
  double theta_margin = 0.9;  ///< see UpdatePolicy::theta_margin, in (0, 1]
  double gate_probability = 0.999;  ///< χ² gate per observation; 0 disables
  /// `observed` (θ on the observed subspace) or `identity` (θ I, the literal eq. 3.39).
  ThetaWeighting theta_weighting = ThetaWeighting::kObserved;

  Status load(const ConfigNode& node);
  /// The options as YAML (one `key: value` per line); load() reads it back unchanged.
  std::string print() const;
  /// c_v² of eq. 3.58 (1 for the EKF).
  double measurementNoiseScale() const;
  /// The policy for CovarianceHelper. Fails when the NH∞ parameters give c_v² ≤ 0.
  Expected<UpdatePolicy> policy() const;
};

/// Outcome of one CovarianceHelper::update.
struct UpdateReport {
  int observations_accepted = 0;
  int observations_rejected = 0;  ///< by the Mahalanobis gate
  double theta_used = 0.0;        ///< θ actually applied (≤ policy θ)
  bool theta_reduced = false;     ///< eq. 3.40 failed with the policy θ and θ was reduced
  int rows = 0;                   ///< rows of the accepted observations
  double nis = 0.0;    ///< joint rᵀ S⁻¹ r of the accepted rows (χ² with `rows` dof)
  int iterations = 0;  ///< linearisations of an iterated update (0: a plain update)
  bool rejected_jointly = false;  ///< an iterated update's joint NIS failed its gate
};

/// Running counts over a filter's lifetime (one per filter instance, no globals).
struct FilterStatistics {
  long updates = 0;
  long theta_reductions = 0;  ///< NH∞ updates where eq. 3.40 forced a smaller θ
  long observations_accepted = 0;
  long observations_rejected = 0;

  void add(const UpdateReport& r) {
    ++updates;
    theta_reductions += r.theta_reduced ? 1 : 0;
    observations_accepted += r.observations_accepted;
    observations_rejected += r.observations_rejected;
  }
};

}  // namespace cvslam
