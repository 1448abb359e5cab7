// DC cooperation that is told the truth (docs/cooperation.md "What is
// fused, and how"): gates that bound the unknown correlation (ciBoundedNis), the innovation
// test over time of a peer (PeerConsistency), the EKF update for estimates whose provenance
// is disjoint from the own state's (CiUpdater::applyIndependent), and the joint covariance
// and provenance that SharedLandmarks carry.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <random>

#include "coop_team_fixture.h"
#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/coop/peer_consistency.h"
#include "cvslam/filter/chi_square.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/covariance_intersection.h"

namespace cvslam {
namespace {

Eigen::Matrix3d randomCovariance(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = n(rng);
  return scale * (A * A.transpose() + 0.2 * Eigen::Matrix3d::Identity());
}

TEST(CiBoundedNis, ScalarCaseIsTheSumOfTheStandardDeviations) {
  // max over ω of d² / (a/ω + b/(1−ω)) = d² / (√a + √b)², attained at ω = √a / (√a + √b).
  Eigen::VectorXd d(1);
  d << 1.3;
  Eigen::MatrixXd a(1, 1), b(1, 1);
  a << 0.04;
  b << 0.36;
  const double exact = 1.3 * 1.3 / std::pow(0.2 + 0.6, 2);
  EXPECT_NEAR(ciBoundedNis(d, a, b, 200), exact, 1e-4 * exact);
  EXPECT_LE(ciBoundedNis(d, a, b), exact * (1.0 + 1e-12));      // every ω is a lower bound
  EXPECT_LT(ciBoundedNis(d, a, b), 1.3 * 1.3 / (0.04 + 0.36));  // looser than independence
}

TEST(CiBoundedNis, GateRejectsAtMostItsProbabilityWhateverTheCorrelation) {
  // Two 3-d estimates of one point with cross-covariance C = ρ L1 L2ᵀ (|ρ| ≤ 1 keeps the joint
  // PSD). The independence gate (P1 + P2) over-rejects when the errors are anti-correlated; the
  // CI-bounded gate stays at or below its 1 % for every ρ.
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Matrix3d P1 = randomCovariance(rng, 0.05), P2 = randomCovariance(rng, 0.2);
  const Eigen::Matrix3d L1 = P1.llt().matrixL(), L2 = P2.llt().matrixL();
  const double gate = chiSquareQuantile(0.99, 3);
  const int draws = 4000;
  for (double rho : {-0.95, -0.5, 0.0, 0.5, 0.95}) {
    int rejected_bounded = 0, rejected_independent = 0;
    for (int k = 0; k < draws; ++k) {
      Eigen::Vector3d u, v;
      for (int i = 0; i < 3; ++i) u(i) = n(rng), v(i) = n(rng);
      // e1 = L1 u, e2 = L2 (ρ u + √(1−ρ²) v): cov(e1, e2) = ρ L1 L2ᵀ.
      const Eigen::Vector3d e1 = L1 * u;
      const Eigen::Vector3d e2 = L2 * (rho * u + std::sqrt(1.0 - rho * rho) * v);
      const Eigen::VectorXd d = e1 - e2;
      rejected_bounded += ciBoundedNis(d, P1, P2) > gate;
      rejected_independent += d.dot((P1 + P2).ldlt().solve(d)) > gate;
    }
    const double rate = static_cast<double>(rejected_bounded) / draws;
    EXPECT_LE(rate, 0.01 + 3.0 * std::sqrt(0.01 * 0.99 / draws)) << "ρ = " << rho;
    if (rho <= -0.5) {
      EXPECT_GT(static_cast<double>(rejected_independent) / draws, 0.03) << "ρ = " << rho;
    }
  }
}

TEST(PeerConsistency, ConsistentPeerKeepsItsWeightOverConfidentOneIsScaled) {
  std::mt19937 rng(3);
  std::chi_squared_distribution<double> chi3(3.0);
  coop::PeerConsistency honest, overconfident;
  int scaled = 0;
  const int exchanges = 500;
  for (int k = 0; k < exchanges; ++k) {
    scaled += honest.add(chi3(rng), 3) > 1.0;
    // Covariances 10× too small: the innovations are √10 times larger than claimed.
    overconfident.add(10.0 * chi3(rng), 3);
  }
  EXPECT_LE(scaled, exchanges / 50) << "a consistent peer is down-weighted at most rarely";
  EXPECT_GT(overconfident.scale(), 5.0);
  EXPECT_LT(overconfident.scale(), 20.0);
  coop::PeerConsistency off({0, 0.999});
  EXPECT_EQ(off.add(1e6, 3), 1.0) << "window 0 disables the test";
}

TEST(CiUpdater, IndependentUpdateIsTheInformationFormFusion) {
  // In the additive chart, where P is the covariance of x − x̂ before and after. (The
  // invariant chart re-expresses the same posterior at the moved mean: test_invariant_error_chart.)
  VisualInertialSlamOptions additive;
  additive.slam.error_chart = ErrorChart::kAdditive;
  const std::unique_ptr<SimulatedTeamRun> run = cooptest::flyPairAlone(6.0, 5, additive);
  ASSERT_NE(run, nullptr);
  const VisualInertialSlam& slam = run->slam(1);
  std::vector<int64_t> ids;
  std::vector<VariableKey> keys;
  for (const StateLandmark& l : slam.stateLandmarks()) {
    ids.push_back(l.id);
    keys.push_back(VariableKey::landmark(static_cast<uint64_t>(l.id)));
    if (ids.size() == 3) break;
  }
  ASSERT_EQ(ids.size(), 3u);
  const Eigen::MatrixXd P = *CovarianceHelper::marginalCovariance(slam.state(), keys);
  Eigen::VectorXd x(9), y(9);
  for (int i = 0; i < 3; ++i) {
    x.segment<3>(3 * i) = slam.stateLandmarks()[static_cast<std::size_t>(i)].p_LinN;
    y.segment<3>(3 * i) = x.segment<3>(3 * i) + Eigen::Vector3d(0.2, -0.1, 0.05 * i);
  }
  std::mt19937 rng(11);
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(9, 9);  // a peer's joint covariance, correlated
  const Eigen::Matrix3d common = randomCovariance(rng, 0.1);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R.block<3, 3>(3 * i, 3 * j) = common;
  for (int i = 0; i < 3; ++i) R.block<3, 3>(3 * i, 3 * i) += randomCovariance(rng, 0.02);

  VisualInertialSlam fused = slam;
  ASSERT_TRUE(fused.fuseIndependent(ids, y, R).ok());
  // P⁺ = (P⁻¹ + R⁻¹)⁻¹ and x⁺ = P⁺ (P⁻¹ x + R⁻¹ y) on the landmarks' block.
  const Eigen::MatrixXd Pi = P.inverse(), Ri = R.inverse();
  const Eigen::MatrixXd P_post = (Pi + Ri).inverse();
  const Eigen::VectorXd x_post = P_post * (Pi * x + Ri * y);
  const Eigen::MatrixXd P_fused = *CovarianceHelper::marginalCovariance(fused.state(), keys);
  EXPECT_LT((P_fused - P_post).cwiseAbs().maxCoeff(), 1e-9 * P.cwiseAbs().maxCoeff());
  for (int i = 0; i < 3; ++i)
    EXPECT_LT(
        (fused.stateLandmarks()[static_cast<std::size_t>(i)].p_LinN - x_post.segment<3>(3 * i))
            .norm(),
        1e-6);
  // Information only adds: the covariance of the vehicle and the map shrinks (P − P⁺ ⪰ 0).
  // (Held landmarks are Schmidt variables: their block stays, their cross-covariances change,
  // so the whole matrix need not shrink.)
  std::vector<int> active;
  for (const StateVariable& v : slam.state().variables()) {
    if (v.key.kind == VariableKey::Kind::kHeldLandmark) continue;
    for (int k = 0; k < v.size; ++k) active.push_back(v.index + k);
  }
  const Eigen::MatrixXd shrink =
      slam.state().covariance()(active, active) - fused.state().covariance()(active, active);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (shrink + shrink.transpose()))
                .eigenvalues()
                .minCoeff(),
            -1e-9);
}

TEST(DcCooperation, FirstExchangeIsIndependentLaterOnesIntersect) {
  // UAV1 and UAV2 share nothing until their first fusion: that exchange is fused by the EKF
  // update; afterwards each holds the other's information and the exchanges are CI.
  std::vector<coop::SharedLandmarks> sent;
  cooptest::TeamOptions o;
  o.transport = [&](int64_t, cooptest::Envelope e) {
    if (e.shared) sent.push_back(*e.shared);
    return std::vector<cooptest::Envelope>{e};
  };
  const cooptest::TeamResult r = cooptest::runTeam(12.0, 5, o);
  ASSERT_TRUE(r.ok);
  int independent = 0, intersected = 0;
  for (const auto& events : r.events)
    for (const coop::CoopEvent& e : events) {
      if (e.kind != coop::CoopEventKind::kFused || e.fused == 0) continue;
      (e.independent ? independent : intersected)++;
      EXPECT_GT(e.nis_dof, 0);
      EXPECT_LE(e.nis, chiSquareQuantile(0.999, e.nis_dof)) << "the joint gate passed it";
    }
  EXPECT_GE(independent, 1);
  EXPECT_LE(independent, 2) << "at most one independent exchange per direction";
  EXPECT_GT(intersected, 0);
  EXPECT_EQ(r.stats[0].fused_independent + r.stats[1].fused_independent, independent);
  ASSERT_FALSE(sent.empty());
  // Provenance names the sender; after the first fusion it names both UAVs.
  for (const coop::SharedLandmarks& s : sent) {
    EXPECT_TRUE(std::binary_search(s.informed_by.begin(), s.informed_by.end(), s.header.agent_id));
    if (s.landmarks.size() >= 2) {
      EXPECT_EQ(s.joint_covariance.rows(), static_cast<Eigen::Index>(3 * s.landmarks.size()));
    }
  }
  EXPECT_EQ(sent.back().informed_by, (std::vector<int>{1, 2}));
}

TEST(DcCooperation, MalformedProvenanceAndJointCovarianceAreRejected) {
  coop::DcCooperation c(1, coop::DcCooperationOptions{}, 7);
  coop::SharedLandmarks s;
  s.header = {2, 0, 1000};
  s.to_agent = 1;
  s.informed_by = {2};
  s.landmarks.push_back({5, {1, 2, 3}, 0.01 * Eigen::Matrix3d::Identity(), {}});
  s.landmarks.push_back({6, {2, 2, 3}, 0.02 * Eigen::Matrix3d::Identity(), {}});
  s.joint_covariance = Eigen::MatrixXd::Zero(6, 6);
  s.joint_covariance.topLeftCorner<3, 3>() = 0.01 * Eigen::Matrix3d::Identity();
  s.joint_covariance.bottomRightCorner<3, 3>() = 0.02 * Eigen::Matrix3d::Identity();
  s.joint_covariance.topRightCorner<3, 3>() = 0.005 * Eigen::Matrix3d::Identity();
  s.joint_covariance.bottomLeftCorner<3, 3>() = 0.005 * Eigen::Matrix3d::Identity();
  EXPECT_TRUE(c.onShared(s));
  auto bad = [&](auto mutate) {
    coop::SharedLandmarks b = s;
    mutate(b);
    return c.onShared(b);
  };
  using Msg = coop::SharedLandmarks;
  EXPECT_TRUE(bad([](Msg& b) { b.informed_by.clear(); })) << "empty: unknown, allowed";
  EXPECT_TRUE(bad([](Msg& b) { b.joint_covariance.resize(0, 0); })) << "marginals only";
  EXPECT_FALSE(bad([](Msg& b) { b.informed_by = {3}; }));     // without the sender
  EXPECT_FALSE(bad([](Msg& b) { b.informed_by = {2, 1}; }));  // not ascending
  EXPECT_FALSE(bad([](Msg& b) { b.informed_by = {0, 2}; }));  // not an agent id
  EXPECT_FALSE(bad([](Msg& b) { b.joint_covariance.conservativeResize(3, 3); }));
  EXPECT_FALSE(bad([](Msg& b) { b.joint_covariance(0, 4) = 0.004; }));  // asymmetric
  EXPECT_FALSE(bad([](Msg& b) {  // diagonal block ≠ the landmark's covariance
    b.joint_covariance(0, 0) = 0.011;
  }));
  EXPECT_FALSE(bad([](Msg& b) {  // cross-covariance too large: not positive definite
    b.joint_covariance.topRightCorner<3, 3>() *= 4.0;
    b.joint_covariance.bottomLeftCorner<3, 3>() *= 4.0;
  }));
  EXPECT_EQ(c.statistics().rejected_invalid, 7);
}

TEST(DcCooperation, OverConfidentPeerIsDownWeightedAndCounted) {
  // UAV2 claims covariances 100× (σ 10×) smaller than its filter's: UAV1's innovation test
  // over time must notice and scale UAV2's R, and must leave an honest UAV2 alone. (It reacts
  // after a window of evidence: the joint gate and CI bound the damage before that; UAV1's
  // final error is printed, 0.36 m forged vs 0.23 m honest, 0.31 m without the test.)
  auto forge = [](int64_t, cooptest::Envelope e) {
    if (e.shared && e.from == 2) {
      for (coop::SharedLandmark& l : e.shared->landmarks) l.covariance *= 0.01;
      e.shared->joint_covariance *= 0.01;
    }
    return std::vector<cooptest::Envelope>{e};
  };
  cooptest::TeamOptions tested, untested, honest;
  tested.transport = untested.transport = forge;
  untested.coop.consistency.window = 0;
  const cooptest::TeamResult t = cooptest::runTeam(12.0, 5, tested);
  const cooptest::TeamResult u = cooptest::runTeam(12.0, 5, untested);
  const cooptest::TeamResult h = cooptest::runTeam(12.0, 5, honest);
  ASSERT_TRUE(t.ok && u.ok && h.ok);
  EXPECT_GT(t.stats[0].peer_down_weighted, 0);
  EXPECT_EQ(u.stats[0].peer_down_weighted, 0);
  EXPECT_EQ(h.stats[0].peer_down_weighted, 0) << "an honest peer is not down-weighted";
  std::printf("UAV1 final error: honest %.3f m, forged tested %.3f m, forged untested %.3f m\n",
              h.final_vehicle_error[0], t.final_vehicle_error[0], u.final_vehicle_error[0]);
}

}  // namespace
}  // namespace cvslam
