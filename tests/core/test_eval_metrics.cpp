#include "cvslam/eval/metrics.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

namespace cvslam {
namespace {

std::vector<TumPose> straightLine(int n, double dt, double speed) {
  std::vector<TumPose> out;
  for (int k = 0; k < n; ++k) {
    TumPose p;
    p.t = k * dt;
    p.p_BinN = {speed * k * dt, 0.0, -5.0};
    out.push_back(p);
  }
  return out;
}

TEST(Metrics, AssociateByTime) {
  const std::vector<double> a = {0.0, 0.1, 0.2, 0.3, 0.5};
  const std::vector<double> b = {0.001, 0.099, 0.25, 0.302, 0.9};
  const auto pairs = associateByTime(a, b, 0.01);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0], std::make_pair(std::size_t{0}, std::size_t{0}));
  EXPECT_EQ(pairs[1], std::make_pair(std::size_t{1}, std::size_t{1}));
  EXPECT_EQ(pairs[2], std::make_pair(std::size_t{3}, std::size_t{3}));
  EXPECT_TRUE(associateByTime(a, {}, 1.0).empty());
}

TEST(Metrics, AteOfAConstantOffsetIsTheOffset) {
  const auto truth = straightLine(50, 0.1, 2.0);
  auto est = truth;
  for (auto& p : est) p.p_BinN += Eigen::Vector3d(1.0, 2.0, 2.0);  // |offset| = 3
  auto ate = absoluteTrajectoryError(est, truth);
  ASSERT_TRUE(ate.ok()) << ate.status().message();
  EXPECT_NEAR(ate->rmse_m, 3.0, 1e-12);
  EXPECT_NEAR(ate->max_m, 3.0, 1e-12);
  EXPECT_EQ(ate->pairs, 50u);
}

TEST(Metrics, AteWithSe3AlignmentRemovesARigidMotion) {
  std::vector<TumPose> truth;
  for (int k = 0; k < 60; ++k) {  // a non-degenerate (helical) path
    TumPose p;
    p.t = 0.1 * k;
    p.p_BinN = {10 * std::cos(0.1 * k), 10 * std::sin(0.1 * k), 0.2 * k};
    truth.push_back(p);
  }
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  auto est = truth;
  for (auto& p : est) p.p_BinN = R * p.p_BinN + Eigen::Vector3d(5, -3, 1);
  AteOptions none;
  EXPECT_GT(absoluteTrajectoryError(est, truth, none)->rmse_m, 1.0);
  AteOptions se3;
  se3.alignment = Alignment::kSE3;
  auto aligned = absoluteTrajectoryError(est, truth, se3);
  ASSERT_TRUE(aligned.ok());
  EXPECT_LT(aligned->rmse_m, 1e-9);
}

namespace {

std::vector<TumPose> helix() {
  std::vector<TumPose> path;
  for (int k = 0; k < 60; ++k) {
    TumPose p;
    p.t = 0.1 * k;
    p.p_BinN = {10 * std::cos(0.1 * k), 10 * std::sin(0.1 * k), 0.2 * k};
    path.push_back(p);
  }
  return path;
}

}  // namespace

// 4-DoF alignment: a yaw + translation is removed exactly, a tilt is not (roll and pitch of a
// visual-inertial estimate are observable and must show in the ATE).
TEST(Metrics, AteWithYawAlignmentRemovesYawAndTranslationOnly) {
  const auto truth = helix();
  const Eigen::Matrix3d yaw = Eigen::AngleAxisd(2.1, Eigen::Vector3d::UnitZ()).matrix();
  auto est = truth;
  for (auto& p : est) p.p_BinN = yaw * p.p_BinN + Eigen::Vector3d(5, -3, 1);
  AteOptions o;
  o.alignment = Alignment::kYaw;
  auto aligned = absoluteTrajectoryError(est, truth, o);
  ASSERT_TRUE(aligned.ok());
  EXPECT_LT(aligned->rmse_m, 1e-9);
  EXPECT_FALSE(aligned->vertical_flipped);
  EXPECT_LT((aligned->R_align * yaw - Eigen::Matrix3d::Identity()).norm(), 1e-9);

  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()).matrix();
  auto tilted = truth;
  for (auto& p : tilted) p.p_BinN = tilt * p.p_BinN;
  EXPECT_GT(absoluteTrajectoryError(tilted, truth, o)->rmse_m, 0.1);
  o.alignment = Alignment::kSE3;
  EXPECT_LT(absoluteTrajectoryError(tilted, truth, o)->rmse_m, 1e-9);
}

// A NED estimate against a z-up truth (EuRoC): the vertical axes are opposite; the yaw
// alignment finds it, says so, and removes the rest.
TEST(Metrics, AteWithYawAlignmentHandlesZUpTruthAgainstNedEstimate) {
  const auto truth = helix();  // z up
  const Eigen::Matrix3d ned_from_zup = Eigen::Vector3d(1, -1, -1).asDiagonal();
  const Eigen::Matrix3d yaw = Eigen::AngleAxisd(-0.8, Eigen::Vector3d::UnitZ()).matrix();
  auto est = truth;
  for (auto& p : est) p.p_BinN = yaw * ned_from_zup * p.p_BinN + Eigen::Vector3d(1, 2, 3);
  AteOptions o;
  o.alignment = Alignment::kYaw;
  auto aligned = absoluteTrajectoryError(est, truth, o);
  ASSERT_TRUE(aligned.ok());
  EXPECT_TRUE(aligned->vertical_flipped);
  EXPECT_LT(aligned->rmse_m, 1e-9);
  EXPECT_NEAR(aligned->R_align.determinant(), 1.0, 1e-12);
  EXPECT_STREQ(alignmentName(Alignment::kYaw), "yaw");
}

TEST(Metrics, AteNeedsPairsWithinTheTolerance) {
  const auto truth = straightLine(10, 0.1, 1.0);
  auto est = truth;
  for (auto& p : est) p.t += 0.05;
  EXPECT_FALSE(absoluteTrajectoryError(est, truth).ok());
  AteOptions loose;
  loose.time_tolerance_s = 0.06;
  EXPECT_TRUE(absoluteTrajectoryError(est, truth, loose).ok());
}

TEST(Metrics, RpeMeasuresScaleDriftPerSegment) {
  const auto truth = straightLine(201, 0.1, 1.0);  // 20 m
  auto est = truth;
  for (auto& p : est) p.p_BinN.x() *= 1.01;  // 1 % scale drift → 0.1 m per 10 m
  auto rpe = relativePoseError(est, truth);
  ASSERT_TRUE(rpe.ok()) << rpe.status().message();
  EXPECT_NEAR(rpe->mean_m, 0.1, 1e-9);
  EXPECT_EQ(rpe->segments, 101u);
  auto offset = truth;
  for (auto& p : offset) p.p_BinN += Eigen::Vector3d(3, 4, 5);
  EXPECT_NEAR(relativePoseError(offset, truth)->mean_m, 0.0, 1e-9) << "a constant offset";
  EXPECT_FALSE(relativePoseError(straightLine(50, 0.1, 1.0), straightLine(50, 0.1, 1.0)).ok())
      << "5 m path, 10 m segment";
}

TEST(Metrics, StateErrorWrapsAngles) {
  Vector9d a = Vector9d::Zero(), b = Vector9d::Zero();
  a(8) = M_PI - 0.1;
  b(8) = -M_PI + 0.1;
  EXPECT_NEAR(stateError(a, b)(8), -0.2, 1e-12);
}

/// Estimates drawn from their own covariance give a mean NEES close to the dimension.
TEST(Metrics, NeesOfConsistentSamplesIsTheDimension) {
  Vector9d sigma;
  sigma << 0.3, 0.4, 0.2, 0.05, 0.05, 0.03, 0.01, 0.01, 0.02;
  Matrix9d C = Matrix9d::Identity();
  C(0, 1) = C(1, 0) = 0.6;
  C(2, 6) = C(6, 2) = -0.4;
  const Matrix9d P = sigma.asDiagonal() * C * sigma.asDiagonal();
  const Matrix9d L = P.llt().matrixL();
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  std::vector<StateRecord> est, truth;
  for (int k = 0; k < 4000; ++k) {
    StateRecord t;
    t.t = 0.05 * k;
    t.x << k, 2, 3, 4, 5, 6, 0.1, 0.2, 0.3;
    Vector9d w;
    for (int i = 0; i < 9; ++i) w(i) = n01(rng);
    StateRecord e = t;
    e.x += L * w;
    e.P = P;
    truth.push_back(t);
    est.push_back(e);
  }
  auto nees = normalisedEstimationErrorSquared(est, truth);
  ASSERT_TRUE(nees.ok()) << nees.status().message();
  // Mean of 4000 χ²(9) samples: σ = sqrt(18/4000) ≈ 0.07.
  EXPECT_NEAR(nees->mean, 9.0, 0.3);
  EXPECT_NEAR(nees->mean_position, 3.0, 0.15);
  EXPECT_EQ(nees->steps, 4000u);
  // Halving the claimed covariance doubles the NEES: an overconfident filter is caught.
  for (auto& e : est) e.P *= 0.5;
  EXPECT_NEAR(normalisedEstimationErrorSquared(est, truth)->mean, 18.0, 0.6);
  // Without velocity truth the NEES has 6 dimensions.
  for (auto& e : est) e.P *= 2.0;
  EXPECT_NEAR(normalisedEstimationErrorSquared(est, truth, 0.01, false)->mean, 6.0, 0.25);
}

TEST(Metrics, NeesSkipsSingularCovariances) {
  std::vector<StateRecord> est(3), truth(3);
  for (int k = 0; k < 3; ++k) est[k].t = truth[k].t = k;
  EXPECT_FALSE(normalisedEstimationErrorSquared(est, truth).ok());  // P = 0 everywhere
  est[2].P = Matrix9d::Identity();
  est[2].x(0) = 2.0;
  auto nees = normalisedEstimationErrorSquared(est, truth);
  ASSERT_TRUE(nees.ok());
  EXPECT_EQ(nees->skipped, 2u);
  EXPECT_DOUBLE_EQ(nees->mean, 4.0);
}

TEST(Metrics, CoAndRcoFollowTheThesisDefinition) {
  // σ = 2 for every state, |error| = 1 except one step with |error| = 4 → co = 2, Rco = 0.5.
  std::vector<StateRecord> est, truth;
  for (int k = 0; k < 10; ++k) {
    StateRecord t, e;
    t.t = e.t = k;
    e.x = Vector9d::Constant(k == 6 ? 4.0 : 1.0);
    e.x.tail<3>() *= 0.1;  // angles: error 0.1 (0.4), σ below
    e.P = Matrix9d::Identity() * 4.0;
    e.P.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * 0.04;
    est.push_back(e);
    truth.push_back(t);
  }
  auto co = consistencyDegree(est, truth);
  ASSERT_TRUE(co.ok()) << co.status().message();
  for (int s = 0; s < 9; ++s) {
    EXPECT_NEAR(co->rco[s], 0.5, 1e-12) << "state " << s;
    EXPECT_NEAR(co->co[0](s), 2.0, 1e-12);
    EXPECT_NEAR(co->fraction_consistent[s], 0.9, 1e-12);
  }
  EXPECT_NEAR(co->sigma_mean[0], 2.0, 1e-12);
  EXPECT_NEAR(co->true_sigma_mean[0], 1.3, 1e-12);
  // An RMS window smooths the true uncertainty: step 6 becomes sqrt((1 + 16)/2).
  ConsistencyOptions o;
  o.window = 2;
  EXPECT_NEAR(consistencyDegree(est, truth, o)->rco[0], 2.0 / std::sqrt(8.5), 1e-12);
}

TEST(Metrics, LandmarkErrorsPerAxis) {
  std::vector<LandmarkRecord> lms;
  for (int i = 0; i < 4; ++i) {
    LandmarkRecord l;
    l.id = i;
    l.truth = Eigen::Vector3d(i, 2 * i, 0);
    l.p_LinN = *l.truth + Eigen::Vector3d(1.0, i % 2 ? 1.0 : -1.0, 0.0);
    lms.push_back(l);
  }
  LandmarkRecord by_id;  // truth supplied separately, by id
  by_id.id = 77;
  by_id.p_LinN = Eigen::Vector3d(5, 5, 5);
  lms.push_back(by_id);
  LandmarkRecord gt;
  gt.id = 77;
  gt.p_LinN = Eigen::Vector3d(4, 5, 5);
  auto r = landmarkErrors(lms, {gt});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->count, 5u);
  EXPECT_NEAR(r->mean_m.x(), 1.0, 1e-12);
  EXPECT_NEAR(r->std_m.x(), 0.0, 1e-12);
  EXPECT_NEAR(r->mean_m.y(), 0.0, 1e-12);
  EXPECT_NEAR(r->std_m.y(), std::sqrt(4.0 / 4.0), 1e-12);  // values ±1, 0: Σ = 4, n − 1 = 4
  EXPECT_FALSE(landmarkErrors({by_id}).ok()) << "no truth at all";
}

TEST(Metrics, Median) {
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(median({})));
}

}  // namespace
}  // namespace cvslam
