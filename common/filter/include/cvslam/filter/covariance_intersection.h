#pragma once
// Covariance intersection (thesis §6.6.4, Julier & Uhlmann): fuses two estimates whose
// cross-correlation is unknown, consistently for every possible correlation (eq. 6.2):
//   P⁻¹ = ω1 P1⁻¹ + ω2 P2⁻¹,   x = P (ω1 P1⁻¹ x1 + ω2 P2⁻¹ x2),   ω1 + ω2 = 1, ω ∈ [0, 1].
// Weights: Niehsen's fast CI (eq. 6.4), the thesis's adaptive CI with the vehicles' position
// covariance traces (eq. 6.5), or the ω minimising trace(P) or det(P) (convex in ω; found by
// golden-section search).

#include <Eigen/Core>
#include <string>

#include "cvslam/core/status.h"

namespace cvslam {

enum class CiMethod {
  kAdaptive,
  kFast,
  kOptimalTrace,
  kOptimalDeterminant,
  /// ω1 minimising the trace of the VEHICLE position covariance after the joint CI update
  /// (jointCiVehiclePositionTrace); on two plain estimates (ciOmega) it is kOptimalTrace.
  kOptimalVehicle,
};

/// "adaptive", "fast", "optimal_trace", "optimal_determinant", "optimal_vehicle".
Expected<CiMethod> parseCiMethod(const std::string& name);
std::string ciMethodName(CiMethod method);

/// eq. 6.4: ω1 = tr P2 / (tr P1 + tr P2).
double fastCiOmega(const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2);

/// eq. 6.5: ω1 = (tr P2 + tr P_UAV2) / (tr P1 + tr P2 + tr P_UAV1 + tr P_UAV2).
double adaptiveCiOmega(const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2, double vehicle_trace1,
                       double vehicle_trace2);

/// ω1 ∈ [0, 1] minimising trace (or det) of the fused covariance, to within tolerance.
double optimalCiOmega(const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2, bool determinant,
                      double tolerance = 1e-6);

/// ω1 by `method` (the vehicle traces are used by kAdaptive only).
double ciOmega(CiMethod method, const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2,
               double vehicle_trace1, double vehicle_trace2);

/// The joint-state CI update of docs/cooperation.md (P⁺⁻¹ = ω1 P⁻¹ + ω2 Hᵀ R⁻¹ H, H selecting the
/// landmarks) seen from the vehicle position: with the prior blocks P_pp (position, 3×3),
/// P_pL (3×3m) and P_LL (3m×3m), the fused position covariance is
///   P_pp/ω1 − (P_pL/ω1) (P_LL/ω1 + R/ω2)⁻¹ (P_Lp/ω1),
/// whose trace this returns (ω1 = 1: tr P_pp). Convex in ω1 (matrix inversion is operator
/// convex and the information is affine in ω1).
double jointCiVehiclePositionTrace(const Eigen::MatrixXd& P_pp, const Eigen::MatrixXd& P_pL,
                                   const Eigen::MatrixXd& P_LL, const Eigen::MatrixXd& R,
                                   double omega1);

/// ω1 ∈ [omega_min, 1] minimising jointCiVehiclePositionTrace (golden section).
double optimalVehicleCiOmega(const Eigen::MatrixXd& P_pp, const Eigen::MatrixXd& P_pL,
                             const Eigen::MatrixXd& P_LL, const Eigen::MatrixXd& R,
                             double omega_min, double tolerance = 1e-6);

/// Normalised squared distance of d = x1 − x2 for two estimates with covariances P1, P2 and
/// UNKNOWN cross-covariance: for every ω ∈ (0, 1), cov(d) ≤ P1/ω + P2/(1 − ω) (the CI bound),
/// so dᵀ cov(d)⁻¹ d ≥ max_ω dᵀ (P1/ω + P2/(1 − ω))⁻¹ d, which this returns (maximised over
/// `steps` − 1 interior ω, each a valid lower bound). A χ² gate on it rejects a consistent pair
/// at most as often as its probability says, whatever the correlation (scalar case:
/// d² / (σ1 + σ2)² instead of the independent d² / (σ1² + σ2²)).
double ciBoundedNis(const Eigen::VectorXd& d, const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2,
                    int steps = 20);

struct CiFusion {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
};

/// eq. 6.2 with ω1 = omega1, ω2 = 1 − omega1. P1, P2 positive definite.
Expected<CiFusion> fuseCovarianceIntersection(const Eigen::VectorXd& x1, const Eigen::MatrixXd& P1,
                                              const Eigen::VectorXd& x2, const Eigen::MatrixXd& P2,
                                              double omega1);

}  // namespace cvslam
