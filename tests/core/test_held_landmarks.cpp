// Held landmarks (slam_state.h, kHeldLandmark; landmark_lifecycle.h): archived landmarks kept in
// the state as Schmidt "consider" variables. The update leaves their mean and covariance alone and
// keeps their cross-covariances exact; archiving and re-activating one is exact; the capacity
// keeps the most recently archived, or those nearest to the vehicles' views.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/io/config_node.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/landmark_lifecycle.h"
#include "cvslam/slam/slam_options.h"
#include "filter_fixtures.h"

namespace cvslam {
namespace {

double minEigenvalue(const Eigen::MatrixXd& P) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .minCoeff();
}

/// Stereo-like observations of the vehicle and landmarks 100 and 101 only (never of 102, the one
/// the tests hold), with residuals of the noise's size.
void observeFirstTwo(const SlamState& state, std::mt19937& rng, MeasurementBatch* batch) {
  batch->reset(state.size(), 8);
  const StateVariable* vehicle = state.find(VariableKey::vehicle(0));
  for (uint64_t id : {100u, 101u}) {
    const int g = batch->addObservation(test::randomMatrix(4, 1, rng), Eigen::Matrix4d::Identity());
    batch->setJacobian(g, *vehicle, test::randomMatrix(4, vehicle->size, rng, 20.0));
    batch->setJacobian(g, *state.find(VariableKey::landmark(id)),
                       test::randomMatrix(4, 3, rng, 20.0));
  }
}

TEST(HeldLandmark, SchmidtUpdateKeepsItsMarginalAndBoundsTheFullUpdate) {
  std::mt19937 rng(11);
  SlamState full = test::randomSlamState(3, rng);
  SlamState held = full;
  ASSERT_TRUE(
      CovarianceHelper::rekey(held, VariableKey::landmark(102), VariableKey::heldLandmark(102))
          .ok());
  EXPECT_EQ(held.landmarkCount(), 2);
  EXPECT_EQ(held.count(VariableKey::Kind::kHeldLandmark), 1);
  const StateVariable h = *held.find(VariableKey::heldLandmark(102));
  const Eigen::Vector3d mean_before = held.value(h);
  const Eigen::Matrix3d cov_before = held.covarianceOf(h);

  for (int k = 0; k < 5; ++k) {
    MeasurementBatch batch;
    const std::mt19937 draw = rng;
    observeFirstTwo(full, rng, &batch);
    ASSERT_TRUE(CovarianceHelper::update(full, batch, UpdatePolicy::ekf(), nullptr).ok());
    rng = draw;  // the same observations for the Schmidt filter
    observeFirstTwo(held, rng, &batch);
    ASSERT_TRUE(CovarianceHelper::update(held, batch, UpdatePolicy::ekf(), nullptr).ok());
  }
  // The held landmark is never corrected, and its own covariance is untouched.
  EXPECT_EQ(Eigen::Vector3d(held.value(h)), mean_before);
  EXPECT_TRUE(held.covarianceOf(h).isApprox(cov_before, 1e-12));
  // The full EKF did learn about it (through its correlation with the vehicle) ...
  const StateVariable f = *full.find(VariableKey::landmark(102));
  EXPECT_LT(full.covarianceOf(f).trace(), 0.9 * cov_before.trace());
  // ... and the Schmidt covariance bounds the full one: it claims no information it lacks.
  const Eigen::MatrixXd margin = held.covariance() - full.covariance();
  EXPECT_GT(minEigenvalue(margin), -1e-9);
  EXPECT_GT(minEigenvalue(held.covariance()), 0.0);
}

/// The update's rank-2m form is the Schmidt filter's Joseph form (I − KH) P (I − KH)ᵀ + K R Kᵀ
/// with the held rows of the optimal gain set to zero, computed densely: with few held landmarks
/// (the triangular product) and with most of the state held (only the corrected columns).
TEST(HeldLandmark, SchmidtUpdateEqualsTheDenseJosephForm) {
  struct Case {
    int landmarks;
    int held;  // the first `held` landmarks, ids 100…
  };
  for (const Case c : {Case{5, 2}, Case{12, 10}, Case{40, 37}}) {
    SCOPED_TRACE(::testing::Message() << c.held << " of " << c.landmarks << " held");
    std::mt19937 rng(12);
    SlamState s = test::randomSlamState(c.landmarks, rng);
    for (int k = 0; k < c.held; ++k) {
      const uint64_t id = 100u + static_cast<uint64_t>(k);
      ASSERT_TRUE(
          CovarianceHelper::rekey(s, VariableKey::landmark(id), VariableKey::heldLandmark(id))
              .ok());
    }
    MeasurementBatch batch;
    test::randomStereoBatch(s, 6, rng, &batch);
    const Eigen::MatrixXd P = s.covariance();
    const Eigen::MatrixXd H = batch.H();
    const Eigen::MatrixXd R = batch.R();
    Eigen::MatrixXd K = P * H.transpose() * (H * P * H.transpose() + R).inverse();
    for (const StateVariable& v : s.variables()) {
      if (v.key.kind == VariableKey::Kind::kHeldLandmark) K.middleRows(v.index, v.size).setZero();
    }
    const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(P.rows(), P.cols()) - K * H;
    const Eigen::MatrixXd joseph = A * P * A.transpose() + K * R * K.transpose();
    const Eigen::VectorXd mean = s.mean() + K * batch.residual();

    ASSERT_TRUE(CovarianceHelper::update(s, batch, UpdatePolicy::ekf(), nullptr).ok());  // no gate
    EXPECT_LT((s.covariance() - joseph).cwiseAbs().maxCoeff(), 1e-10 * P.cwiseAbs().maxCoeff());
    EXPECT_EQ(s.covariance(), s.covariance().transpose());  // exactly symmetric
    EXPECT_LT((s.mean() - mean).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(HeldLandmark, ArchivingAndReactivatingIsExact) {
  std::mt19937 rng(12);
  SlamState state = test::randomSlamState(3, rng);
  const SlamState before = state;
  LandmarkArchive archive;
  LandmarkBook book;
  book.add(101, {7,
                 1,
                 2,
                 {1, 2, 3},
                 state.value(*state.find(VariableKey::landmark(101))),
                 Eigen::Vector3d::UnitZ(),
                 false});
  archiveLandmark(state, archive, 101, book.remove(101), 5'000'000, /*held_capacity=*/4);
  EXPECT_FALSE(state.has(VariableKey::landmark(101)));
  EXPECT_TRUE(isHeld(state, 101));
  ASSERT_NE(archive.find(101), nullptr);
  EXPECT_EQ(archive.find(101)->index, 7u);
  EXPECT_TRUE(archive.find(101)->covariance.isApprox(
      before.covarianceOf(*before.find(VariableKey::landmark(101)))));
  EXPECT_EQ(state.landmarkCount(), 2);

  ASSERT_TRUE(reactivateLandmark(state, book, archive, 101));
  EXPECT_FALSE(archive.contains(101));
  EXPECT_FALSE(isHeld(state, 101));
  ASSERT_NE(book.find(101), nullptr);
  EXPECT_EQ(book.find(101)->index, 7u);
  // Same slots, same mean, same covariance: the correlations never left.
  EXPECT_EQ(state.mean(), before.mean());
  EXPECT_EQ(state.covariance(), before.covariance());
  EXPECT_EQ(state.find(VariableKey::landmark(101))->index,
            before.find(VariableKey::landmark(101))->index);
}

TEST(HeldLandmark, CapacityKeepsTheMostRecentlyArchived) {
  std::mt19937 rng(13);
  SlamState state = test::randomSlamState(4, rng);
  LandmarkArchive archive;
  // 102 leaves first, then 100, then 103: with room for two, 102 is marginalised.
  archiveLandmark(state, archive, 102, std::nullopt, 1'000'000, 2);
  archiveLandmark(state, archive, 100, std::nullopt, 2'000'000, 2);
  const Eigen::Matrix3d cov_100 = state.covarianceOf(*state.find(VariableKey::heldLandmark(100)));
  archiveLandmark(state, archive, 103, std::nullopt, 3'000'000, 2);
  EXPECT_EQ(state.count(VariableKey::Kind::kHeldLandmark), 2);
  EXPECT_FALSE(isHeld(state, 102));
  EXPECT_TRUE(isHeld(state, 100));
  EXPECT_TRUE(isHeld(state, 103));
  EXPECT_EQ(state.landmarkCount(), 1);
  EXPECT_EQ(state.size(), 9 + 3 * 3);
  // Every one stays in the archive; a marginalised one re-enters the thesis's way.
  EXPECT_EQ(archive.size(), 3u);
  LandmarkBook book;
  ASSERT_TRUE(reactivateLandmark(state, book, archive, 102));
  const StateVariable v = *state.find(VariableKey::landmark(102));
  EXPECT_TRUE(state.covariance().block(0, v.index, v.index, 3).isZero());
  EXPECT_TRUE(state.covarianceOf(*state.find(VariableKey::heldLandmark(100))).isApprox(cov_100));
  // Capacity 0 is the thesis's archive: marginalised at once.
  archiveLandmark(state, archive, 101, std::nullopt, 4'000'000, 0);
  EXPECT_FALSE(isHeld(state, 101));
  EXPECT_FALSE(state.has(VariableKey::landmark(101)));
}

// The joint map's eviction (SlamOptions::HeldEviction::kNearest): the held landmark farthest
// from every vehicle's m* leaves first, whatever its age; equally far, the older leaves.
TEST(HeldLandmark, NearestEvictionKeepsTheLandmarksNearSomeVehiclesView) {
  std::mt19937 rng(15);
  SlamState state = test::randomSlamState(4, rng);
  const auto at = [&](uint64_t id) { return state.value(*state.find(VariableKey::landmark(id))); };
  // One vehicle's m* on 102 (archived first), another's on 103 (archived last).
  const std::vector<Eigen::Vector3d> m_stars = {at(102), at(103)};
  ASSERT_GT((at(100) - at(102)).norm(), 0.1);
  ASSERT_GT((at(101) - at(103)).norm(), 0.1);
  SlamState two = state;
  LandmarkArchive archive;
  int64_t t_us = 0;
  for (uint64_t id : {102u, 100u, 101u, 103u})
    archiveLandmark(two, archive, static_cast<int64_t>(id), std::nullopt, t_us += 1'000'000, 2,
                    m_stars);
  // By age 101 and 103 would stay; by distance the two under the vehicles' views do.
  EXPECT_TRUE(isHeld(two, 102));
  EXPECT_TRUE(isHeld(two, 103));
  EXPECT_EQ(two.count(VariableKey::Kind::kHeldLandmark), 2);
  EXPECT_EQ(archive.size(), 4u);
  // Room for one, both at distance 0: the older (102) leaves.
  LandmarkArchive archive_one;
  archiveLandmark(state, archive_one, 102, std::nullopt, 1'000'000, 1, m_stars);
  archiveLandmark(state, archive_one, 103, std::nullopt, 2'000'000, 1, m_stars);
  EXPECT_FALSE(isHeld(state, 102));
  EXPECT_TRUE(isHeld(state, 103));
}

// Anchors (SlamOptions::anchor_landmarks): beyond the recent ones, older held landmarks stay
// spread over the map; of the two nearest each other, the less well known leaves.
TEST(HeldLandmark, AnchorsStaySpreadOverTheMap) {
  const auto build = [](double var_10, double var_11) {
    SlamState state;
    EXPECT_TRUE(CovarianceHelper::addVariable(state, VariableKey::vehicle(0),
                                              Eigen::VectorXd::Zero(9),
                                              Eigen::MatrixXd::Identity(9, 9))
                    .ok());
    // Along x: 0, 10 and 11 (a dense pair), 20, 30; archived in that order.
    const std::vector<std::pair<double, double>> x_var = {
        {0.0, 1.0}, {10.0, var_10}, {11.0, var_11}, {20.0, 1.0}, {30.0, 1.0}};
    for (std::size_t i = 0; i < x_var.size(); ++i) {
      EXPECT_TRUE(CovarianceHelper::addVariable(state, VariableKey::landmark(200 + i),
                                                Eigen::Vector3d(x_var[i].first, 0, 0),
                                                Eigen::Matrix3d::Identity() * x_var[i].second)
                      .ok());
    }
    return state;
  };
  // Archives all five with room for one recent held landmark and `anchors` anchors; each stays
  // in the archive whatever is held.
  const auto archiveAll = [&build](double var_10, double var_11, int anchors) {
    SlamState state = build(var_10, var_11);
    LandmarkArchive archive;
    for (int64_t i = 0; i < 5; ++i)
      archiveLandmark(state, archive, 200 + i, std::nullopt, (i + 1) * 1'000'000, 1, {}, anchors);
    EXPECT_EQ(archive.size(), 5u);
    return state;
  };
  // One recent (x = 30) and three anchors: the pair at 10 / 11 loses its less known member.
  const SlamState state = archiveAll(1.0, 2.0, 3);
  EXPECT_EQ(state.count(VariableKey::Kind::kHeldLandmark), 4);
  for (int64_t id : {200, 201, 203, 204}) EXPECT_TRUE(isHeld(state, id)) << id;
  EXPECT_FALSE(isHeld(state, 202));
  const SlamState other = archiveAll(2.0, 1.0, 3);
  EXPECT_FALSE(isHeld(other, 201));
  EXPECT_TRUE(isHeld(other, 202));
  // Two anchors: the spread pair 0 / 20 stays, whatever the ages.
  const SlamState two = archiveAll(1.0, 2.0, 2);
  for (int64_t id : {200, 203, 204}) EXPECT_TRUE(isHeld(two, id)) << id;
  EXPECT_EQ(two.count(VariableKey::Kind::kHeldLandmark), 3);
  // No anchors: the most recent only, as before.
  const SlamState none = archiveAll(1.0, 2.0, 0);
  EXPECT_EQ(none.count(VariableKey::Kind::kHeldLandmark), 1);
  EXPECT_TRUE(isHeld(none, 204));
}

TEST(HeldLandmark, AnchorOptionIsReadAndChecked) {
  const auto load = [](const char* yaml, SlamOptions* o) {
    auto node = ConfigNode::fromString(yaml, "slam.yaml");
    EXPECT_TRUE(node.ok());
    return o->load(*node);
  };
  SlamOptions o;
  ASSERT_TRUE(load("anchor_landmarks: 7\n", &o).ok());
  EXPECT_EQ(o.anchor_landmarks, 7);
  for (const char* bad : {"anchor_landmarks: -1\n", "held_landmarks: 0\nanchor_landmarks: 5\n"}) {
    SlamOptions b;
    const Status s = load(bad, &b);
    ASSERT_FALSE(s.ok()) << bad;
    EXPECT_NE(s.message().find("anchor_landmarks"), std::string::npos) << s.message();
  }
}

TEST(HeldLandmark, RekeyRefusesMissingAndTakenKeys) {
  std::mt19937 rng(14);
  SlamState state = test::randomSlamState(2, rng);
  EXPECT_FALSE(
      CovarianceHelper::rekey(state, VariableKey::landmark(7), VariableKey::heldLandmark(7)).ok());
  EXPECT_FALSE(
      CovarianceHelper::rekey(state, VariableKey::landmark(100), VariableKey::landmark(101)).ok());
  EXPECT_TRUE(state.has(VariableKey::landmark(100)));
}

}  // namespace
}  // namespace cvslam
