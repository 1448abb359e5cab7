#include "cvslam/geometry/euler.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "jacobian_check.h"

namespace cvslam {
namespace {

TEST(Euler, MatchesComposedFrameRotations) {
  const Eigen::Vector3d e(0.3, -0.2, 1.1);
  // Frame rotation about an axis = transpose of the active rotation.
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(e(0), Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(e(1), Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(e(2), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d expected = Rx.transpose() * Ry.transpose() * Rz.transpose();
  EXPECT_TRUE(rotationNavToBody(e).isApprox(expected, 1e-12));
  EXPECT_TRUE((rotationNavToBody(e) * rotationBodyToNav(e)).isIdentity(1e-12));
}

TEST(Euler, YawOnlyRotatesNorthIntoBodyFrame) {
  // Heading east (ψ = 90°): the north axis is to the body's left (−y in FRD).
  const Eigen::Vector3d north_in_body =
      rotationNavToBody(Eigen::Vector3d(0, 0, M_PI / 2)) * Eigen::Vector3d::UnitX();
  EXPECT_TRUE(north_in_body.isApprox(Eigen::Vector3d(0, -1, 0), 1e-12));
}

TEST(Euler, RoundTripsThroughRotation) {
  for (const Eigen::Vector3d& e : {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(-2.5, 1.2, -3.0),
                                   Eigen::Vector3d(3.0, -1.4, 2.9)}) {
    const Eigen::Vector3d back = eulerFromRotationNavToBody(rotationNavToBody(e));
    EXPECT_TRUE(rotationNavToBody(back).isApprox(rotationNavToBody(e), 1e-12));
    EXPECT_NEAR(back(1), e(1), 1e-12);
  }
}

TEST(Euler, RatesMatchFiniteDifferenceOfRotation) {
  // d/dt R_BtoN = R_BtoN [ω]x ; check eq. 2.4 by integrating a small step.
  const Eigen::Vector3d e(0.2, 0.4, -0.7), w(0.3, -0.5, 0.8);
  const double dt = 1e-6;
  const Eigen::Matrix3d R0 = rotationBodyToNav(e);
  Eigen::Matrix3d W;
  W << 0, -w(2), w(1), w(2), 0, -w(0), -w(1), w(0), 0;
  const Eigen::Matrix3d Rdot_expected = R0 * W;
  const Eigen::Matrix3d Rdot = (rotationBodyToNav<double>(e + eulerRates(e, w) * dt) -
                                rotationBodyToNav<double>(e - eulerRates(e, w) * dt)) /
                               (2 * dt);
  EXPECT_TRUE(Rdot.isApprox(Rdot_expected, 1e-6));
}

TEST(Euler, WrapAngle) {
  EXPECT_NEAR(wrapAngle(3 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrapAngle(-M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrapAngle(0.5 - 4 * M_PI), 0.5, 1e-12);
}

TEST(JacobianCheck, DetectsAWrongJacobian) {
  auto f = [](const Eigen::VectorXd& x) {
    Eigen::VectorXd y(2);
    y << x(0) * x(1), std::sin(x(0));
    return y;
  };
  Eigen::VectorXd x(2);
  x << 0.7, -1.3;
  Eigen::MatrixXd J(2, 2);
  J << x(1), x(0), std::cos(x(0)), 0.0;
  EXPECT_TRUE(test::jacobianMatches(f, x, J));
  J(1, 0) += 1e-3;
  EXPECT_FALSE(test::jacobianMatches(f, x, J));
}

}  // namespace
}  // namespace cvslam
