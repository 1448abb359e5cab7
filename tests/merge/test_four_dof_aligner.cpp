#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "cvslam/merge/four_dof_aligner.h"
#include "merge/merge_test_scenes.h"

namespace cvslam::merge {
namespace {

using scenes::makeScene;
using scenes::relationNees;
using scenes::SceneOptions;

// The 99 % band of the mean of N χ²₄ draws: 4 ± 2.58 √(8 / N).
constexpr int kTrials = 200;
const double kBand = 2.58 * std::sqrt(8.0 / kTrials);

TEST(FourDofAligner, NoiseFreeCorrespondencesGiveTheRelationExactly) {
  Rng rng(11);
  SceneOptions o;
  scenes::Scene s = makeScene(rng, o);
  // Noise-free: both sides at the truth, the covariances kept (they only weigh).
  const Eigen::Matrix3d R = s.truth.rotation();
  for (std::size_t k = 0; k < s.points.a.size(); ++k)
    s.points.b[k] = R.transpose() * (s.points.a[k] - s.truth.translation());
  auto r = FourDofAligner().align(s.points);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_LT(relationDifference(r->relation.x, s.truth.x).norm(), 1e-9);
  EXPECT_EQ(r->inliers.size(), s.points.a.size());
}

TEST(FourDofAligner, MonteCarloRelationErrorIsInsideTheChiSquareBand) {
  Rng rng(21);
  double nees = 0.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const scenes::Scene s = makeScene(rng, SceneOptions());
    auto r = FourDofAligner().align(s.points);
    ASSERT_TRUE(r.ok()) << r.status().message();
    nees += relationNees(r->relation, s.truth);
  }
  nees /= kTrials;
  std::printf("relation NEES over %d trials: %.2f (band %.2f..%.2f)\n", kTrials, nees, 4.0 - kBand,
              4.0 + kBand);
  EXPECT_GT(nees, 4.0 - kBand);
  EXPECT_LT(nees, 4.0 + kBand);
}

TEST(FourDofAligner, WrongMatchesAreLeftOutAndTheRelationStaysConsistent) {
  Rng rng(31);
  SceneOptions o;
  o.landmarks = 60;
  o.outlier_fraction = 0.35;
  double nees = 0.0;
  int outliers_kept = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const scenes::Scene s = makeScene(rng, o);
    auto r = FourDofAligner().align(s.points);
    ASSERT_TRUE(r.ok()) << r.status().message();
    nees += relationNees(r->relation, s.truth);
    for (int k : r->inliers) outliers_kept += s.outlier[static_cast<std::size_t>(k)] ? 1 : 0;
  }
  nees /= kTrials;
  std::printf("with 35 %% wrong matches: NEES %.2f, wrong matches kept %d\n", nees, outliers_kept);
  EXPECT_LT(nees, 4.0 + kBand);
  EXPECT_GT(nees, 4.0 - kBand);
  // A wrong match passes the 3-dof gate only when it lands near its false partner by chance.
  EXPECT_LT(outliers_kept, kTrials / 10) << outliers_kept;
}

TEST(FourDofAligner, CorrelatedLandmarksNeedTheirJointCovariance) {
  // An error common to all of A's landmarks (its vehicle's) moves the relation as a whole: the
  // joint covariance accounts for it; treating the landmarks as independent does not.
  Rng rng(41);
  SceneOptions o;
  o.common_sigma = 0.3;
  double joint = 0.0, independent = 0.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    scenes::Scene s = makeScene(rng, o);
    auto r = FourDofAligner().align(s.points);
    ASSERT_TRUE(r.ok()) << r.status().message();
    joint += relationNees(r->relation, s.truth);
    for (std::size_t u = 0; u < s.points.a.size(); ++u)
      for (std::size_t v = 0; v < s.points.a.size(); ++v)
        if (u != v)
          s.points.cov_a
              .block<3, 3>(static_cast<Eigen::Index>(3 * u), static_cast<Eigen::Index>(3 * v))
              .setZero();
    for (std::size_t u = 0; u < s.points.a.size(); ++u)
      s.points.cov_a.block<3, 3>(static_cast<Eigen::Index>(3 * u),
                                 static_cast<Eigen::Index>(3 * u)) -=
          o.common_sigma * o.common_sigma * Eigen::Matrix3d::Identity();
    auto ri = FourDofAligner().align(s.points);
    if (ri.ok()) independent += relationNees(ri->relation, s.truth);
  }
  joint /= kTrials;
  independent /= kTrials;
  std::printf("common error 0.3 m: NEES %.2f with the joint covariance, %.2f without\n", joint,
              independent);
  EXPECT_GT(joint, 4.0 - kBand);
  EXPECT_LT(joint, 4.0 + kBand);
  EXPECT_GT(independent, 2.0 * (4.0 + kBand)) << "independent NEES " << independent;
}

TEST(FourDofAligner, UnrelatedPointSetsAreNeverAligned) {
  // Two maps of different places: no relation should pass.
  Rng rng(51);
  int accepted = 0;
  for (int trial = 0; trial < 100; ++trial) {
    SceneOptions o;
    o.outlier_fraction = 1.0;
    const scenes::Scene s = makeScene(rng, o);
    accepted += FourDofAligner().align(s.points).ok() ? 1 : 0;
  }
  EXPECT_EQ(accepted, 0);
}

TEST(FourDofAligner, MalformedInputIsRefusedWithAReason) {
  Rng rng(61);
  const scenes::Scene good = makeScene(rng, SceneOptions());
  const FourDofAligner aligner;
  scenes::Scene s = good;
  s.points.b.pop_back();
  EXPECT_NE(aligner.align(s.points).status().message().find("length"), std::string::npos);
  s = good;
  s.points.a[3](1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(aligner.align(s.points).status().message().find("non-finite"), std::string::npos);
  s = good;
  s.points.cov_b = Eigen::MatrixXd::Identity(3, 3);
  EXPECT_NE(aligner.align(s.points).status().message().find("covariances"), std::string::npos);
  s = good;
  s.points.a.resize(5);
  s.points.b.resize(5);
  s.points.cov_a = s.points.cov_a.topLeftCorner(15, 15).eval();
  s.points.cov_b = s.points.cov_b.topLeftCorner(15, 15).eval();
  EXPECT_NE(aligner.align(s.points).status().message().find("need 12"), std::string::npos);
  // Every landmark in one spot: the yaw is not observable; refused, not guessed.
  SceneOptions tiny;
  tiny.box = 0.4;
  EXPECT_FALSE(aligner.align(makeScene(rng, tiny).points).ok());
}

}  // namespace
}  // namespace cvslam::merge
