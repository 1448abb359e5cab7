#include "cvslam/filter/covariance_intersection.h"

#include <algorithm>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

#include "cvslam/core/golden_section.h"

namespace cvslam {

namespace {

/// Fused covariance for weight w (ω1); I1, I2 are the information matrices.
Eigen::MatrixXd fusedCovariance(const Eigen::MatrixXd& I1, const Eigen::MatrixXd& I2, double w) {
  const Eigen::MatrixXd I = w * I1 + (1.0 - w) * I2;
  return I.ldlt().solve(Eigen::MatrixXd::Identity(I.rows(), I.cols()));
}

double ratio(double a, double b) {
  return a + b > 0.0 ? a / (a + b) : 0.5;
}
}  // namespace

Expected<CiMethod> parseCiMethod(const std::string& name) {
  if (name == "adaptive") return CiMethod::kAdaptive;
  if (name == "fast") return CiMethod::kFast;
  if (name == "optimal_trace") return CiMethod::kOptimalTrace;
  if (name == "optimal_determinant") return CiMethod::kOptimalDeterminant;
  if (name == "optimal_vehicle") return CiMethod::kOptimalVehicle;
  return Status::Error("unknown ci_method '" + name +
                       "' (adaptive, fast, optimal_trace, optimal_determinant or optimal_vehicle)");
}

std::string ciMethodName(CiMethod method) {
  switch (method) {
    case CiMethod::kAdaptive:
      return "adaptive";
    case CiMethod::kFast:
      return "fast";
    case CiMethod::kOptimalTrace:
      return "optimal_trace";
    case CiMethod::kOptimalDeterminant:
      return "optimal_determinant";
    case CiMethod::kOptimalVehicle:
      return "optimal_vehicle";
  }
  return "adaptive";
}

double fastCiOmega(const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2) {
  return ratio(P2.trace(), P1.trace());  // eq. 6.4
}

double adaptiveCiOmega(const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2, double vehicle_trace1,
                       double vehicle_trace2) {
  return ratio(P2.trace() + vehicle_trace2, P1.trace() + vehicle_trace1);  // eq. 6.5
}

double optimalCiOmega(const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2, bool determinant,
                      double tolerance) {
  const Eigen::MatrixXd I1 = P1.ldlt().solve(Eigen::MatrixXd::Identity(P1.rows(), P1.cols()));
  const Eigen::MatrixXd I2 = P2.ldlt().solve(Eigen::MatrixXd::Identity(P2.rows(), P2.cols()));
  // Both criteria are convex in ω (trace of the inverse of an affine PD family; −log det of
  // an affine PD family), so golden-section search finds the global minimum on [0, 1].
  auto cost = [&](double w) {
    if (determinant) {
      const Eigen::MatrixXd I = w * I1 + (1.0 - w) * I2;
      return -std::log(I.determinant());
    }
    return fusedCovariance(I1, I2, w).trace();
  };
  const double w = minimizeGoldenSection(cost, 0.0, 1.0, tolerance).x;
  // The minimum may sit on the boundary (one estimate dominates).
  const double f0 = cost(0.0), f_one = cost(1.0), fw = cost(w);
  if (f0 <= fw && f0 <= f_one) return 0.0;
  if (f_one <= fw) return 1.0;
  return w;
}

double ciOmega(CiMethod method, const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2,
               double vehicle_trace1, double vehicle_trace2) {
  switch (method) {
    case CiMethod::kAdaptive:
      return adaptiveCiOmega(P1, P2, vehicle_trace1, vehicle_trace2);
    case CiMethod::kFast:
      return fastCiOmega(P1, P2);
    case CiMethod::kOptimalTrace:
    case CiMethod::kOptimalVehicle:
      return optimalCiOmega(P1, P2, false);
    case CiMethod::kOptimalDeterminant:
      return optimalCiOmega(P1, P2, true);
  }
  return 0.5;
}

double jointCiVehiclePositionTrace(const Eigen::MatrixXd& P_pp, const Eigen::MatrixXd& P_pL,
                                   const Eigen::MatrixXd& P_LL, const Eigen::MatrixXd& R,
                                   double omega1) {
  if (omega1 >= 1.0) return P_pp.trace();
  const double w2 = 1.0 - omega1;
  const Eigen::MatrixXd S = P_LL / omega1 + R / w2;
  const Eigen::MatrixXd PpL = P_pL / omega1;
  return (P_pp / omega1 - PpL * S.ldlt().solve(PpL.transpose())).trace();
}

double optimalVehicleCiOmega(const Eigen::MatrixXd& P_pp, const Eigen::MatrixXd& P_pL,
                             const Eigen::MatrixXd& P_LL, const Eigen::MatrixXd& R,
                             double omega_min, double tolerance) {
  auto cost = [&](double w) { return jointCiVehiclePositionTrace(P_pp, P_pL, P_LL, R, w); };
  const double w = minimizeGoldenSection(cost, omega_min, 1.0, tolerance).x;
  if (cost(1.0) <= cost(w)) return 1.0;
  if (cost(omega_min) <= cost(w)) return omega_min;
  return w;
}

double ciBoundedNis(const Eigen::VectorXd& d, const Eigen::MatrixXd& P1, const Eigen::MatrixXd& P2,
                    int steps) {
  double best = 0.0;
  for (int k = 1; k < steps; ++k) {
    const double w = static_cast<double>(k) / steps;
    const Eigen::LDLT<Eigen::MatrixXd> S(P1 / w + P2 / (1.0 - w));
    if (S.info() != Eigen::Success) continue;
    best = std::max(best, d.dot(S.solve(d)));
  }
  return best;
}

Expected<CiFusion> fuseCovarianceIntersection(const Eigen::VectorXd& x1, const Eigen::MatrixXd& P1,
                                              const Eigen::VectorXd& x2, const Eigen::MatrixXd& P2,
                                              double omega1) {
  const auto n = x1.size();
  if (x2.size() != n || P1.rows() != n || P1.cols() != n || P2.rows() != n || P2.cols() != n)
    return Status::Error("covariance intersection: size mismatch");
  if (!(omega1 >= 0.0 && omega1 <= 1.0))
    return Status::Error("covariance intersection: omega1 must be in [0, 1]");
  const Eigen::LLT<Eigen::MatrixXd> l1(P1), l2(P2);
  if (l1.info() != Eigen::Success || l2.info() != Eigen::Success)
    return Status::Error("covariance intersection: covariance not positive definite");
  const Eigen::MatrixXd Id = Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd I1 = l1.solve(Id), I2 = l2.solve(Id);
  CiFusion f;
  f.P = fusedCovariance(I1, I2, omega1);  // eq. 6.2
  f.P = 0.5 * (f.P + f.P.transpose());
  f.x = f.P * (omega1 * I1 * x1 + (1.0 - omega1) * I2 * x2);
  return f;
}

}  // namespace cvslam
