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

namespace cvslam::coop {

enum class CiMethod { kAdaptive, kFast, kOptimalTrace, kOptimalDeterminant };

/// "adaptive", "fast", "optimal_trace", "optimal_determinant".
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

struct CiFusion {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
};

/// eq. 6.2 with ω1 = omega1, ω2 = 1 − omega1. P1, P2 positive definite.
Expected<CiFusion> fuseCovarianceIntersection(const Eigen::VectorXd& x1, const Eigen::MatrixXd& P1,
                                              const Eigen::VectorXd& x2, const Eigen::MatrixXd& P2,
                                              double omega1);

}  // namespace cvslam::coop
