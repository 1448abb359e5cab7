#include "cvslam/eval/team_evaluation.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cvslam/coop/coop_log.h"
#include "cvslam/io/run_writer.h"

namespace cvslam {
namespace {

namespace fs = std::filesystem;

// Two agents fly circles; agent 2 starts unknown, its own frame at kFrame2 in the world.
// Known offsets make every figure computable by hand.
const Eigen::Vector4d kFrame2(10.0, -5.0, 0.5, 0.7);
constexpr double kOffset1 = 0.1, kOffset2 = 0.2;  // own-frame estimate errors [m]
constexpr double kMergeAt = 20.0;                 // [s]

Vector9d worldState(double t, int agent) {
  Vector9d x = Vector9d::Zero();
  const double a = 0.2 * t + agent;
  x << 15.0 * std::cos(a), 15.0 * std::sin(a), -8.0 - agent, 3.0, 0, 0, 0, 0,
      std::remainder(a + M_PI / 2, 2 * M_PI);
  return x;
}

Vector9d toFrame(const Eigen::Vector4d& f, Vector9d x_world) {
  x_world.head<3>() =
      Eigen::AngleAxisd(-f(3), Eigen::Vector3d::UnitZ()) * (x_world.head<3>() - f.head<3>());
  x_world(8) = std::remainder(x_world(8) - f(3), 2 * M_PI);
  return x_world;
}

Vector9d toWorld(const Eigen::Vector4d& f, Vector9d x_own) {
  x_own.head<3>() =
      Eigen::AngleAxisd(f(3), Eigen::Vector3d::UnitZ()) * x_own.head<3>() + f.head<3>();
  x_own(8) = std::remainder(x_own(8) + f(3), 2 * M_PI);
  return x_own;
}

coop::RelationRecord relationRow(double t, int peer, const char* verdict, const Eigen::Vector4d& x,
                                 const Eigen::Vector4d& sigma) {
  coop::RelationRecord r;
  r.t_us = static_cast<int64_t>(t * 1e6);
  r.peer = peer;
  r.verdict = verdict;
  r.reason = "test, with a comma";
  r.candidate.x = x;
  r.candidate.P = sigma.cwiseAbs2().asDiagonal();
  return r;
}

class TeamEvaluationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("cvslam_team_eval_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name()))
               .string();
    fs::remove_all(dir_);
    RunInfo info;
    info.mode = "dc";
    info.agents = {1, 2};
    info.frames_in_world[2] = kFrame2;
    ASSERT_TRUE(writeRunInfo(dir_, info).ok());
    for (int id : {1, 2}) {
      AgentRunWriter w;
      ASSERT_TRUE(w.open(dir_, id).ok());
      const Eigen::Vector4d frame = id == 2 ? kFrame2 : Eigen::Vector4d::Zero();
      for (int k = 0; k <= 400; ++k) {
        const double t = 0.1 * k;
        const Vector9d truth = toFrame(frame, worldState(t, id));
        Vector9d x = truth;
        x(id - 1) += id == 1 ? kOffset1 : kOffset2;  // agent 1 off in N, agent 2 in its own E
        ASSERT_TRUE(w.addState(t, x, Matrix9d::Identity()).ok());
        ASSERT_TRUE(w.addTruth(t, truth).ok());
        // In agent 1's frame (the world) from the merge on, through the true relation.
        if (t >= kMergeAt) ASSERT_TRUE(w.addTeamState(t, 1, toWorld(frame, x)).ok());
      }
      ASSERT_TRUE(w.close().ok());
    }
    // Agent 2's verifications of agent 1's frame: the true relation (1 → 2) is the inverse
    // of agent 2's frame in the world.
    merge::FrameRelation own;
    own.x = kFrame2;
    const Eigen::Vector4d truth = own.inverse().x;
    const Eigen::Vector4d s(0.1, 0.1, 0.1, 0.01);
    std::ofstream log(dir_ + "/agent_2/relations.csv");
    log << coop::relationsCsvHeader();
    coop::writeRelationsCsvRow(log, relationRow(5.0, 1, "failed", Eigen::Vector4d::Zero(), s));
    coop::writeRelationsCsvRow(
        log, relationRow(12.0, 1, "adopted", truth + Eigen::Vector4d(0.1, 0, 0, 0), s));  // NEES 1
    coop::writeRelationsCsvRow(
        log, relationRow(14.0, 1, "rejected", truth + Eigen::Vector4d(0, 0, 0, 0.5), s));  // 2500
  }
  void TearDown() override {
    if (!std::getenv("CVSLAM_KEEP_TEST_RUNS")) fs::remove_all(dir_);
  }
  std::string dir_;
};

TEST_F(TeamEvaluationTest, FiguresOfATeamWhoseFramesAreKnownByConstruction) {
  auto team = evaluateTeam(dir_, "");
  ASSERT_TRUE(team.ok()) << team.status().message();
  ASSERT_EQ(team->agents.size(), 2u);
  const TeamAgentEvaluation& a1 = team->agents[0];
  const TeamAgentEvaluation& a2 = team->agents[1];
  EXPECT_NEAR(*a1.own_ate_m, kOffset1, 1e-6);
  EXPECT_NEAR(*a2.own_ate_m, kOffset2, 1e-6);
  ASSERT_TRUE(a2.root && a2.merged_at_s && a2.coverage && a2.team_ate_m);
  EXPECT_EQ(*a2.root, 1);
  EXPECT_NEAR(*a2.merged_at_s, kMergeAt, 1e-6);
  EXPECT_NEAR(*a2.coverage, 0.5, 1e-6);
  // A rigid error of the own frame stays rigid in the root's: its size is kept.
  EXPECT_NEAR(*a1.team_ate_m, kOffset1, 1e-6);
  EXPECT_NEAR(*a2.team_ate_m, kOffset2, 1e-6);
  // One alignment for both: no better than each alone, no worse than none.
  ASSERT_TRUE(team->team_ate_aligned_m && team->root);
  EXPECT_EQ(*team->root, 1);
  const double unaligned = std::sqrt((kOffset1 * kOffset1 + kOffset2 * kOffset2) / 2);
  EXPECT_LT(*team->team_ate_aligned_m, unaligned);
  EXPECT_GT(*team->team_ate_aligned_m, 0.02);

  ASSERT_TRUE(a2.relations);
  const RelationCheck& r = *a2.relations;
  EXPECT_EQ(r.failed, 1);
  EXPECT_EQ(r.verified, 2);
  EXPECT_EQ(r.adopted, 1);
  ASSERT_EQ(r.nees.size(), 2u);
  EXPECT_NEAR(r.nees[0], 1.0, 1e-6);
  EXPECT_NEAR(r.nees[1], 2500.0, 1e-3);
  EXPECT_EQ(r.over_bound, 1);
  EXPECT_EQ(r.wrong_adopted, 0);
  ASSERT_EQ(r.first_adoption_s.size(), 1u);
  EXPECT_NEAR(r.first_adoption_s[0], 12.0, 1e-9);
  EXPECT_FALSE(a1.relations);  // agent 1 wrote no relations.csv

  const Json j = teamSummaryJson(*team);
  EXPECT_EQ(j["agents"]["2"]["relations"]["wrong_adopted"], 0);
  EXPECT_NE(teamSummaryTable(*team).find("team (frame of agent 1)"), std::string::npos);
}

TEST_F(TeamEvaluationTest, AWrongAdoptionIsCountedAndABrokenLogIsNamed) {
  std::ofstream(dir_ + "/agent_2/relations.csv", std::ios::app)
      << "20,1,adopted,9,9,0,1,2,3,4,0,0,1,0,0,0,1,0,0,1,0,1,far off\n";
  auto team = evaluateTeam(dir_, "");
  ASSERT_TRUE(team.ok()) << team.status().message();
  EXPECT_EQ(team->agents[1].relations->wrong_adopted, 1);

  std::ofstream(dir_ + "/agent_2/relations.csv", std::ios::app) << "21,1,adopted,nan\n";
  auto broken = evaluateTeam(dir_, "");
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.status().message().find("agent_2/relations.csv:6:"), std::string::npos)
      << broken.status().message();

  std::ofstream(dir_ + "/agent_1/trajectory_team.tum", std::ios::trunc) << "0 0 0 0 0 0 0 1\n";
  auto no_frame = evaluateTeam(dir_, "");
  ASSERT_FALSE(no_frame.ok());
  EXPECT_NE(no_frame.status().message().find("trajectory_team.tum:1: expected '# frame: agent_"),
            std::string::npos)
      << no_frame.status().message();
}

}  // namespace
}  // namespace cvslam
