// The frame relation between two agents from their own filters' maps (merge/four_dof_aligner.h):
// two UAVs fly a scenario at the feature level (true ids stand in for place recognition); the
// second agent's map is then expressed in a frame of its own (a known yaw and translation
// away, as if it had started there), and the relation is recovered from the landmarks both
// mapped with the filters' joint covariances. Its error must be consistent with its stated
// covariance over seeds: a relation that claims more than it knows would wreck a merge.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "cvslam/core/random.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/merge/four_dof_aligner.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "shipped_config.h"
#include "test_paths.h"

namespace cvslam {
namespace {

struct MapPoint {
  Eigen::Vector3d p;
  Eigen::Matrix3d covariance;  // the marginal the filter reports
  VariableKey key;
};

std::map<uint32_t, MapPoint> mapByIndex(const VisualInertialSlam& slam) {
  std::map<uint32_t, MapPoint> out;
  for (const StateLandmark& l : slam.stateLandmarks())
    out.emplace(l.index, MapPoint{l.p_LinN, l.covariance,
                                  VariableKey::landmark(static_cast<uint64_t>(l.id))});
  return out;
}

// The relation NEES of one seeded flight, or a negative number when the maps share too little.
// `independent`: the same with each landmark's marginal only (correlations dropped).
double relationNees(const std::string& scenario_file, uint64_t seed, double duration, int* shared,
                    double* independent) {
  auto scenario = sim::Scenario::loadFile(test::sourceDir() + "/config/scenarios/" + scenario_file);
  EXPECT_TRUE(scenario.ok()) << scenario.status().message();
  scenario->seed = seed;
  scenario->duration = std::min(scenario->duration, duration);
  scenario->agents.resize(2);
  VisualInertialSlamOptions options;
  auto cfg = test::shippedAgentConfig();
  EXPECT_TRUE(cfg.ok() && options.load(*cfg).ok());
  // The whole map of each flight (a full map, bounded as for one room): what a place match
  // against a peer's keyframe sees, rather than the k nearest landmarks of this instant.
  options.map.kind = MapKind::kFull;
  options.map.max_landmarks = 500;
  auto run = SimulatedTeamRun::create(*scenario, options);
  EXPECT_TRUE(run.ok()) << run.status().message();
  EXPECT_TRUE((*run)->run([](const SimulatedFrame&) { return Status::Ok(); }).ok());
  const VisualInertialSlam& a = (*run)->slam(0);
  const VisualInertialSlam& b = (*run)->slam(1);
  const auto map_a = mapByIndex(a);
  const auto map_b = mapByIndex(b);
  std::vector<VariableKey> keys_a, keys_b;
  Eigen::Matrix3d first_marginal = Eigen::Matrix3d::Zero();
  merge::AlignmentPoints points;
  // B's own frame: a yaw and a translation away from the team frame (B's map x_B' = T⁻¹ x_B).
  Rng rng(seed * 7919);
  merge::FrameRelation truth;
  truth.x << rng.uniform(-40, 40), rng.uniform(-40, 40), rng.uniform(-2, 2),
      rng.uniform(-M_PI, M_PI);
  const merge::FrameRelation to_own = truth.inverse();
  for (const auto& [index, pa] : map_a) {
    const auto it = map_b.find(index);
    if (it == map_b.end()) continue;
    if (points.a.empty()) first_marginal = pa.covariance;
    points.a.push_back(pa.p);
    points.b.push_back(to_own.apply(it->second.p));
    keys_a.push_back(pa.key);
    keys_b.push_back(it->second.key);
  }
  *shared = static_cast<int>(points.a.size());
  if (points.a.size() < 12) return -1.0;
  auto Ja = CovarianceHelper::marginalCovariance(a.state(), keys_a);
  auto Jb = CovarianceHelper::marginalCovariance(b.state(), keys_b);
  EXPECT_TRUE(Ja.ok() && Jb.ok());
  if (!Ja.ok() || !Jb.ok()) return -1.0;
  // The joint block's diagonal is each landmark's reported marginal (one chart for both).
  EXPECT_LT((Ja->topLeftCorner<3, 3>() - first_marginal).norm(), 1e-9);
  points.cov_a = *Ja;
  // Rotated into B's own frame: blockdiag(R) J blockdiag(R)ᵀ.
  const Eigen::Matrix3d R = to_own.rotation();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(Jb->rows(), Jb->cols());
  for (Eigen::Index k = 0; k < B.rows(); k += 3) B.block<3, 3>(k, k) = R;
  points.cov_b = B * *Jb * B.transpose();
  const auto nees = [&](const merge::AlignmentPoints& p) {
    auto aligned = merge::FourDofAligner().align(p);
    EXPECT_TRUE(aligned.ok()) << aligned.status().message();
    if (!aligned.ok()) return -1.0;
    const merge::FrameRelation::Vector4d e =
        merge::relationDifference(aligned->relation.x, truth.x);
    return e.dot(aligned->relation.P.ldlt().solve(e));
  };
  merge::AlignmentPoints marginals = points;
  for (Eigen::Index r = 0; r < points.cov_a.rows(); r += 3)
    for (Eigen::Index c = 0; c < points.cov_a.cols(); c += 3)
      if (r != c) {
        marginals.cov_a.block<3, 3>(r, c).setZero();
        marginals.cov_b.block<3, 3>(r, c).setZero();
      }
  *independent = nees(marginals);
  return nees(points);
}

TEST(MapAlignment, RelationFromTwoFiltersMapsIsConsistentOverSeeds) {
  const int seeds = 10;
  double sum = 0.0, sum_independent = 0.0;
  int used = 0;
  for (uint64_t seed = 301; seed < 301 + seeds; ++seed) {
    int shared = 0;
    double independent = 0.0;
    const double nees = relationNees("coop_pair.yaml", seed, 12.0, &shared, &independent);
    std::printf("seed %llu: %d shared landmarks, relation NEES %.2f (marginals only: %.2f)\n",
                static_cast<unsigned long long>(seed), shared, nees, independent);
    if (nees < 0.0) continue;
    sum += nees;
    sum_independent += independent;
    ++used;
  }
  ASSERT_GE(used, seeds - 1);
  const double mean = sum / used;
  // The 99 % band of the mean of `used` χ²₄ draws.
  const double band = 2.58 * std::sqrt(8.0 / used);
  std::printf("relation NEES over %d flights: %.2f (band %.2f..%.2f); marginals only: %.2f\n", used,
              mean, 4.0 - band, 4.0 + band, sum_independent / used);
  EXPECT_LT(mean, 4.0 + band);
  EXPECT_GT(mean, 4.0 - band);
  // One filter's landmarks share its vehicle's errors: dropping their correlations makes the
  // relation claim far more than it knows (why SHARED carries the joint covariance).
  EXPECT_GT(sum_independent / used, 4.0 + band);
}

}  // namespace
}  // namespace cvslam
