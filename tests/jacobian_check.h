#pragma once
// Shared Jacobian check: compares an analytic Jacobian with central finite
// differences and FAILS the test on mismatch, printing the worst entry.
//
//   EXPECT_TRUE(cvslam::test::jacobianMatches(f, x0, J_analytic));
// where f maps Eigen::VectorXd -> Eigen::VectorXd.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <sstream>

namespace cvslam::test {

/// Central-difference Jacobian of f at x with step h (per coordinate, scaled by |x_i|).
template <typename F>
Eigen::MatrixXd numericalJacobian(F&& f, const Eigen::VectorXd& x, double h = 1e-6) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double step = h * std::max(1.0, std::abs(x(i)));
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += step;
    xm(i) -= step;
    J.col(i) = (f(xp) - f(xm)) / (2.0 * step);
  }
  return J;
}

/// Passes when every entry satisfies |J_a − J_n| ≤ abs_tol + rel_tol · max(|J_a|, |J_n|).
template <typename F>
::testing::AssertionResult jacobianMatches(F&& f, const Eigen::VectorXd& x,
                                           const Eigen::MatrixXd& J_analytic, double rel_tol = 1e-5,
                                           double abs_tol = 1e-6, double h = 1e-6) {
  const Eigen::MatrixXd J_num = numericalJacobian(f, x, h);
  if (J_num.rows() != J_analytic.rows() || J_num.cols() != J_analytic.cols()) {
    return ::testing::AssertionFailure()
           << "Jacobian size " << J_analytic.rows() << "x" << J_analytic.cols()
           << " but the function gives " << J_num.rows() << "x" << J_num.cols();
  }
  double worst = 0.0;
  Eigen::Index wr = 0, wc = 0;
  for (Eigen::Index r = 0; r < J_num.rows(); ++r) {
    for (Eigen::Index c = 0; c < J_num.cols(); ++c) {
      const double a = J_analytic(r, c), n = J_num(r, c);
      if (!std::isfinite(a)) {
        return ::testing::AssertionFailure()
               << "non-finite analytic entry (" << r << "," << c << ")";
      }
      const double excess =
          std::abs(a - n) - (abs_tol + rel_tol * std::max(std::abs(a), std::abs(n)));
      if (excess > worst) {
        worst = excess;
        wr = r;
        wc = c;
      }
    }
  }
  if (worst > 0.0) {
    std::ostringstream os;
    os << "Jacobian mismatch, worst at (" << wr << "," << wc << "): analytic " << J_analytic(wr, wc)
       << " vs numerical " << J_num(wr, wc) << "\nanalytic:\n"
       << J_analytic << "\nnumerical:\n"
       << J_num;
    return ::testing::AssertionFailure() << os.str();
  }
  return ::testing::AssertionSuccess();
}

}  // namespace cvslam::test
