#include "cvslam/slam/loop_alignment.h"

#include <gtest/gtest.h>

#include <random>

namespace cvslam {
namespace {

TEST(LoopAlignment, RecoversYawAndTranslation) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  LoopAlignment truth;
  truth.yaw = 0.3;
  truth.pivot = Eigen::Vector3d(10, -4, -10);
  truth.translation = Eigen::Vector3d(-20, 7, 1.5);
  std::vector<LoopPair> pairs;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d p = truth.pivot + Eigen::Vector3d(u(rng), u(rng), 10.0 + 0.2 * u(rng));
    pairs.push_back({p, truth.apply(p)});
  }
  auto a = alignLoop(pairs, truth.pivot);
  ASSERT_TRUE(a.ok());
  EXPECT_NEAR(a->yaw, truth.yaw, 1e-12);
  EXPECT_TRUE(a->translation.isApprox(truth.translation, 1e-12));
  EXPECT_LT(a->rms_residual, 1e-12);
  // Positive yaw turns north towards east (NED, seen from above: clockwise).
  LoopAlignment quarter;
  quarter.yaw = M_PI / 2;
  EXPECT_TRUE(quarter.apply(Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
}

TEST(LoopAlignment, NoisyPairsGiveALeastSquaresFit) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  LoopAlignment truth;
  truth.yaw = -0.1;
  truth.translation = Eigen::Vector3d(3, 2, 0);
  std::vector<LoopPair> pairs;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), 10.0);
    pairs.push_back({p, truth.apply(p) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))});
  }
  auto a = alignLoop(pairs, Eigen::Vector3d::Zero());
  ASSERT_TRUE(a.ok());
  EXPECT_NEAR(a->yaw, truth.yaw, 0.02);
  EXPECT_LT((a->translation - truth.translation).norm(), 0.1);
  EXPECT_NEAR(a->rms_residual, 0.05 * std::sqrt(3.0), 0.04);
}

TEST(LoopAlignment, RejectsTooFewOrNonFinitePairs) {
  EXPECT_FALSE(
      alignLoop({{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()}}, Eigen::Vector3d::Zero())
          .ok());
  std::vector<LoopPair> bad = {{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()},
                               {Eigen::Vector3d::Constant(NAN), Eigen::Vector3d::Ones()}};
  EXPECT_FALSE(alignLoop(bad, Eigen::Vector3d::Zero()).ok());
}

}  // namespace
}  // namespace cvslam
