#include <gtest/gtest.h>

#include <cmath>

#include "cvslam/merge/frame_relation.h"
#include "jacobian_check.h"

namespace cvslam::merge {
namespace {

FrameRelation sampleRelation() {
  FrameRelation r;
  r.x << 12.0, -4.0, 0.7, 2.4;
  Eigen::Matrix4d A;
  A << 0.3, 0.01, 0.0, 0.02, 0.01, 0.2, 0.0, -0.01, 0.0, 0.0, 0.05, 0.0, 0.02, -0.01, 0.0, 0.01;
  r.P = A * A.transpose() + 1e-3 * Eigen::Matrix4d::Identity();
  return r;
}

TEST(FrameRelation, ApplyJacobiansMatchFiniteDifferences) {
  const FrameRelation rel = sampleRelation();
  const Eigen::Vector3d p(3.0, -7.5, 1.2);
  FrameRelation::Matrix34d J_x;
  Eigen::Matrix3d J_p;
  rel.apply(p, &J_x, &J_p);
  EXPECT_TRUE(test::jacobianMatches(
      [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
        FrameRelation r = rel;
        r.x = x;
        return r.apply(p);
      },
      rel.x, J_x));
  EXPECT_TRUE(test::jacobianMatches(
      [&](const Eigen::VectorXd& q) -> Eigen::VectorXd { return rel.apply(q); }, p, J_p));
}

TEST(FrameRelation, InverseUndoesAndItsCovarianceIsTheLinearisedOne) {
  const FrameRelation rel = sampleRelation();
  const FrameRelation inv = rel.inverse();
  const Eigen::Vector3d p(-2.0, 5.0, 0.3);
  EXPECT_LT((inv.apply(rel.apply(p)) - p).norm(), 1e-12);
  const auto f = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    FrameRelation r;
    r.x = x;
    return r.inverse().x;
  };
  const Eigen::MatrixXd J = test::numericalJacobian(f, rel.x);
  EXPECT_LT((inv.P - J * rel.P * J.transpose()).norm(), 1e-8);
  // Inverse twice: the relation and its covariance back.
  const FrameRelation back = inv.inverse();
  EXPECT_LT(relationDifference(back.x, rel.x).norm(), 1e-12);
  EXPECT_LT((back.P - rel.P).norm(), 1e-10);
}

TEST(FrameRelation, ComposeChainsPointsAndAddsBothCovariances) {
  const FrameRelation ab = sampleRelation();
  FrameRelation bc;
  bc.x << -3.0, 8.0, -0.2, -1.1;
  bc.P = 0.02 * Eigen::Matrix4d::Identity();
  const FrameRelation ac = ab.compose(bc);
  const Eigen::Vector3d p(1.0, 2.0, 3.0);
  EXPECT_LT((ac.apply(p) - ab.apply(bc.apply(p))).norm(), 1e-12);
  Eigen::Matrix<double, 8, 1> x;
  x << ab.x, bc.x;
  const auto f = [](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    FrameRelation a, b;
    a.x = v.head<4>();
    b.x = v.tail<4>();
    return a.compose(b).x;
  };
  const Eigen::MatrixXd J = test::numericalJacobian(f, x);
  Eigen::Matrix<double, 8, 8> P = Eigen::Matrix<double, 8, 8>::Zero();
  P.topLeftCorner<4, 4>() = ab.P;
  P.bottomRightCorner<4, 4>() = bc.P;
  EXPECT_LT((ac.P - J * P * J.transpose()).norm(), 1e-8);
}

TEST(FrameRelation, DifferenceWrapsTheYaw) {
  FrameRelation::Vector4d a, b;
  a << 0, 0, 0, M_PI - 0.05;
  b << 0, 0, 0, -M_PI + 0.05;
  EXPECT_NEAR(relationDifference(a, b)(3), -0.1, 1e-12);
}

}  // namespace
}  // namespace cvslam::merge
