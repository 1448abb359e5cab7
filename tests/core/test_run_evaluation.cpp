#include "cvslam/eval/run_evaluation.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "ci_facility.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/run_reader.h"
#include "fake_run.h"
#include "test_paths.h"

namespace cvslam {
namespace {

namespace fs = std::filesystem;

class RunEvaluation : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("cvslam_eval_" + std::to_string(::getpid()) + "_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name())))
               .string();
    fs::remove_all(dir_);
    test::writeFakeRun(dir_ + "/run", options_);
  }
  // CVSLAM_KEEP_TEST_RUNS=1 keeps the folders for a look at the figures.
  void TearDown() override {
    if (!std::getenv("CVSLAM_KEEP_TEST_RUNS")) fs::remove_all(dir_);
  }
  std::string dir_;
  test::FakeRunOptions options_;
};

TEST_F(RunEvaluation, KnownFiguresOfTheFakeRun) {
  auto agents = evaluateRun(dir_ + "/run", "");
  ASSERT_TRUE(agents.ok()) << agents.status().message();
  ASSERT_EQ(agents->size(), 2u);
  const AgentEvaluation& a = (*agents)[0];
  EXPECT_EQ(a.id, 1);
  // Position noise σ = (0.3, 0.4, 0.2) → expected ATE sqrt(0.29) ≈ 0.539 m.
  ASSERT_TRUE(a.ate_rmse_m);
  EXPECT_NEAR(*a.ate_rmse_m, std::sqrt(0.29), 0.04);
  // INS drifts 0.01 m per step along x: RMS over k = 0..399 is 0.01 sqrt(399·799/6).
  ASSERT_TRUE(a.ins_ate_rmse_m);
  EXPECT_NEAR(*a.ins_ate_rmse_m, 0.01 * std::sqrt(399.0 * 799.0 / 6.0), 1e-4);
  ASSERT_TRUE(a.rpe_m_per_10m);
  EXPECT_GT(*a.rpe_m_per_10m, 0.3);
  EXPECT_LT(*a.rpe_m_per_10m, 2.0);
  ASSERT_TRUE(a.nees_mean);
  EXPECT_NEAR(*a.nees_mean, 9.0, 0.7);  // 400 samples: σ of the mean ≈ 0.21
  ASSERT_TRUE(a.consistency);
  for (double r : a.consistency->rco) EXPECT_LT(r, 1.0) << "some step always beats σ";
  ASSERT_TRUE(a.landmark_error);
  EXPECT_EQ(a.landmark_error->count, 30u);
  EXPECT_NEAR(a.landmark_error->mean_m.x(), 0.1, 0.03);
  EXPECT_NEAR(a.landmark_error->mean_m.y(), -0.2, 1e-9);
  EXPECT_NEAR(a.landmark_error->std_m.x(), 0.05, 0.02);
  EXPECT_NEAR(a.landmark_error->std_m.z(), 0.0, 1e-9);
  EXPECT_EQ(a.max_state_size, 69);
  EXPECT_DOUBLE_EQ(*a.frame_time_ms_median, 12.0);
  EXPECT_NEAR(*a.bytes_sent_per_s, 400.0 * 1000.0 / 39.9, 1e-6);
  EXPECT_TRUE(a.notes.empty());
}

// A ground station's record names the batches each UAV sent: the figures of a UAV it followed
// for a fraction of them say so (coverage, a note), those of a UAV it followed throughout not.
TEST_F(RunEvaluation, AGroundStationRecordSaysOverHowMuchOfEachFlightItsFiguresAre) {
  std::ofstream(dir_ + "/run/stats.json")
      << R"({"batches": 410, "agents": {"1": {"batches": 400, "rejected": 0},
            "2": {"batches": 400, "rejected": 7500, "dropped_per_reason": {"decode": 100}}}})";
  auto agents = evaluateRun(dir_ + "/run", "");
  ASSERT_TRUE(agents.ok()) << agents.status().message();
  ASSERT_EQ(agents->size(), 2u);
  ASSERT_TRUE((*agents)[0].coverage);
  EXPECT_DOUBLE_EQ(*(*agents)[0].coverage, 1.0);
  EXPECT_TRUE((*agents)[0].notes.empty());
  ASSERT_TRUE((*agents)[1].coverage);
  EXPECT_DOUBLE_EQ(*(*agents)[1].coverage, 400.0 / 8000.0);
  ASSERT_EQ((*agents)[1].notes.size(), 1u);
  EXPECT_NE((*agents)[1].notes[0].find("400 of 8000"), std::string::npos);
  ASSERT_TRUE((*agents)[1].covered_s);
  EXPECT_NEAR(*(*agents)[1].covered_s, 39.9, 1e-6);
  const Json summary = summaryJson(RunInfo{}, *agents, {});
  EXPECT_DOUBLE_EQ(summary["agents"]["2"]["coverage"].get<double>(), 0.05);
  EXPECT_NE(summaryTable(*agents).find("cover[%]"), std::string::npos);
}

// Time columns keep every microsecond at any epoch: a run stamped in EuRoC time (≈ 1.4e9 s,
// 0.1 s steps) reads back with every row in order and gives the same figures.
TEST_F(RunEvaluation, EurocEpochTimestampsKeepTheirResolution) {
  test::FakeRunOptions o = options_;
  o.t0 = 1403715273.262143;
  test::writeFakeRun(dir_ + "/euroc_epoch", o);
  auto agents = evaluateRun(dir_ + "/euroc_epoch", "");
  ASSERT_TRUE(agents.ok()) << agents.status().message();
  const AgentEvaluation& a = (*agents)[0];
  EXPECT_EQ(a.steps, 400u);
  ASSERT_TRUE(a.ate_rmse_m && a.nees_mean);
  EXPECT_NEAR(*a.ate_rmse_m, std::sqrt(0.29), 0.04);
  EXPECT_NEAR(*a.nees_mean, 9.0, 0.7);
  EXPECT_TRUE(a.notes.empty());
  auto run = readAgentRun(dir_ + "/euroc_epoch", 1);
  ASSERT_TRUE(run.ok()) << run.status().message();
  ASSERT_EQ(run->states.size(), 400u);
  EXPECT_NEAR(run->states[1].t - run->states[0].t, 0.1, 1e-6);
  EXPECT_NEAR(run->states.back().t, o.t0 + 39.9, 1e-6);
}

TEST_F(RunEvaluation, SummaryJsonHasTheDesignKeys) {
  auto agents = evaluateRun(dir_ + "/run", "");
  ASSERT_TRUE(agents.ok());
  auto info = readRunInfo(dir_ + "/run");
  ASSERT_TRUE(info.ok());
  const Json j = summaryJson(*info, *agents, {});
  auto back = parseJson(j.dump(2));  // what the file holds parses
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->at("mode").get<std::string>(), "dc");
  EXPECT_EQ(back->at("filter").get<std::string>(), "nhinf");
  ASSERT_TRUE(back->at("agents").contains("1"));
  const Json& a1 = back->at("agents").at("1");
  for (const char* key : {"ate_rmse_m", "ins_ate_rmse_m", "rpe_m_per_10m", "nees_mean",
                          "max_state_size", "frame_time_ms_median", "bytes_sent_per_s"}) {
    ASSERT_TRUE(a1.contains(key)) << key;
    EXPECT_TRUE(a1.at(key).is_number()) << key;
  }
  for (const char* key : {"landmark_error_mean_m", "landmark_error_std_m"}) {
    ASSERT_TRUE(a1.contains(key)) << key;
    EXPECT_EQ(a1.at(key).size(), 3u) << key;
  }
  ASSERT_TRUE(a1.at("rco").is_object());
  EXPECT_TRUE(a1.at("rco").at("yaw").is_number());
  ASSERT_TRUE(back->at("agents").contains("2"));
}

TEST_F(RunEvaluation, MissingPiecesGiveNullsWithNotes) {
  fs::remove(dir_ + "/run/agent_1/truth.csv");
  fs::remove(dir_ + "/run/agent_1/ins_trajectory.tum");
  fs::remove(dir_ + "/run/agent_1/stats.json");
  std::ofstream(dir_ + "/run/agent_1/stats.json") << "{}";
  auto agents = evaluateRun(dir_ + "/run", "");
  ASSERT_TRUE(agents.ok()) << agents.status().message();
  const AgentEvaluation& a = (*agents)[0];
  EXPECT_FALSE(a.ate_rmse_m);
  EXPECT_FALSE(a.ins_ate_rmse_m);
  EXPECT_FALSE(a.nees_mean);
  EXPECT_FALSE(a.frame_time_ms_median);
  EXPECT_FALSE(a.bytes_sent_per_s);
  EXPECT_TRUE(a.landmark_error) << "landmark truth is in landmarks.csv";
  EXPECT_FALSE(a.notes.empty());
  const Json j = summaryJson(RunInfo{}, *agents, {});
  EXPECT_TRUE(j.at("mode").is_null());
  EXPECT_TRUE(j.at("agents").at("1").at("ate_rmse_m").is_null());
}

TEST_F(RunEvaluation, NisPerDegreeOfFreedomFromEvents) {
  // Σ nis / Σ nis_dof over events.csv, ground truth or not; none from a run written before
  // the columns existed; a negative NIS is an error naming the file and line.
  const std::string head =
      "t,observations,updated,rejected,initialised,archived,reactivated,loop_landmarks,"
      "loop_closure,loop_refused,theta_reduced,state_size";
  std::ofstream(dir_ + "/run/agent_1/events.csv")
      << head
      << ",nis,nis_dof\n0.1,3,3,0,0,0,0,0,0,0,0,15,10.0,12\n0.2,0,0,0,0,0,0,0,0,0,0,15,0,0\n"
      << "0.3,2,2,0,0,0,0,0,0,0,0,15,14.0,8\n";
  std::ofstream(dir_ + "/run/agent_2/events.csv") << head << "\n0.1,3,3,0,0,0,0,0,0,0,0,15\n";
  fs::remove(dir_ + "/run/agent_1/truth.csv");
  auto agents = evaluateRun(dir_ + "/run", "");
  ASSERT_TRUE(agents.ok()) << agents.status().message();
  ASSERT_TRUE((*agents)[0].nis_per_dof);
  EXPECT_DOUBLE_EQ(*(*agents)[0].nis_per_dof, 24.0 / 20.0);
  EXPECT_FALSE((*agents)[0].ate_rmse_m);
  EXPECT_FALSE((*agents)[1].nis_per_dof);
  EXPECT_DOUBLE_EQ(summaryJson(RunInfo{}, *agents, {}).at("agents").at("1").at("nis_per_dof"), 1.2);
  EXPECT_NE(summaryTable(*agents).find("NIS/dof"), std::string::npos);
  std::ofstream(dir_ + "/run/agent_1/events.csv")
      << head << ",nis,nis_dof\n0.1,3,3,0,0,0,0,0,0,0,0,15,-1.0,12\n";
  auto bad = evaluateRun(dir_ + "/run", "");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("events.csv:2"), std::string::npos)
      << bad.status().message();
}

TEST_F(RunEvaluation, SeparateGroundTruthFolder) {
  // Move truth.csv into a separate GT folder, as a simulator would write it.
  for (int id : {1, 2}) {
    const std::string gt = dir_ + "/gt/agent_" + std::to_string(id);
    fs::create_directories(gt);
    fs::rename(dir_ + "/run/agent_" + std::to_string(id) + "/truth.csv", gt + "/truth.csv");
  }
  auto with_gt = evaluateRun(dir_ + "/run", dir_ + "/gt");
  ASSERT_TRUE(with_gt.ok()) << with_gt.status().message();
  EXPECT_TRUE((*with_gt)[1].ate_rmse_m);
  auto missing = evaluateRun(dir_ + "/run", dir_ + "/nowhere");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("no such ground-truth folder"), std::string::npos);
}

// Real data: the EuRoC ground truth lives in its own world frame, so the estimate needs an
// SE(3) alignment. A rigidly moved copy of the truth must give ATE ≈ 0 after alignment.
TEST_F(RunEvaluation, RealEurocGroundTruthWithSe3Alignment) {
  const std::string euroc = test::sharedDataDir() + "/euroc_micro";
  bool has_velocity = false;
  auto gt = readGroundTruth(euroc, 1, &has_velocity);
  ASSERT_TRUE(gt.ok()) << gt.status().message();
  ASSERT_GT(gt->size(), 100u);
  const std::string run = dir_ + "/real";
  fs::create_directories(run + "/agent_1");
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0, 0.3, 1).normalized()).matrix();
  std::vector<TumPose> est;
  for (const StateRecord& s : *gt) {
    TumPose p = tumPoseFromState(s.t, s.x);
    p.p_BinN = R * p.p_BinN + Eigen::Vector3d(1, -2, 3);
    p.q_BtoN = Eigen::Quaterniond(R) * p.q_BtoN;
    est.push_back(p);
  }
  ASSERT_TRUE(writeTumTrajectory(run + "/agent_1/trajectory.tum", est).ok());
  std::ofstream(run + "/agent_1/landmarks.csv") << "id,x,y,z\n";
  std::ofstream(run + "/agent_1/stats.json") << "{}";
  RunEvaluationOptions o;
  auto plain = evaluateRun(run, euroc, o);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_GT(*(*plain)[0].ate_rmse_m, 1.0);
  o.alignment = Alignment::kSE3;
  auto aligned = evaluateRun(run, euroc, o);
  ASSERT_TRUE(aligned.ok());
  EXPECT_LT(*(*aligned)[0].ate_rmse_m, 1e-5);
  // RPE is frame independent: zero with or without alignment (the path is a few metres, so
  // use a short segment).
  o.rpe_segment_m = 0.5;
  o.alignment = Alignment::kNone;
  auto rpe = evaluateRun(run, euroc, o);
  ASSERT_TRUE(rpe.ok());
  ASSERT_TRUE((*rpe)[0].rpe_m_per_10m) << (*rpe)[0].notes.front();
  EXPECT_LT(*(*rpe)[0].rpe_m_per_10m, 1e-5);
}

// NEES and co compare in the estimator's frame: with an alignment they are null, and say why
// (the ATE is still there).
TEST_F(RunEvaluation, AlignedEvaluationHasNoNees) {
  RunEvaluationOptions o;
  o.alignment = Alignment::kYaw;
  auto agents = evaluateRun(dir_ + "/run", "", o);
  ASSERT_TRUE(agents.ok()) << agents.status().message();
  const AgentEvaluation& a = (*agents)[0];
  EXPECT_TRUE(a.ate_rmse_m);
  EXPECT_FALSE(a.nees_mean);
  EXPECT_FALSE(a.consistency);
  ASSERT_FALSE(a.notes.empty());
  EXPECT_NE(a.notes.back().find("aligned evaluation: NEES and co are null"), std::string::npos);
}

TEST(RunEvaluationOptions, Load) {
  auto cfg = ConfigNode::fromString("{alignment: se3, co_window: 5}", "e.yaml");
  ASSERT_TRUE(cfg.ok());
  RunEvaluationOptions o;
  ASSERT_TRUE(o.load(*cfg).ok());
  EXPECT_EQ(o.alignment, Alignment::kSE3);
  EXPECT_EQ(o.co_window, 5);
  auto bad = ConfigNode::fromString("{alignment: sim3, rpe_segment_m: 0}", "e.yaml");
  EXPECT_FALSE(RunEvaluationOptions{}.load(*bad).ok());
}

/// Runs a shell command, returns its exit status.
int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST_F(RunEvaluation, ToolEndToEnd) {
  const std::string tool = std::string(CVSLAM_BINARY_DIR) + "/tools/cvslam_eval";
  if (!fs::exists(tool)) CVSLAM_SKIP_UNLESS_CI() << "build the cvslam_eval target first";
  const std::string json = dir_ + "/summary.json";
  EXPECT_EQ(
      run(tool + " --run " + dir_ + "/run --summary-json " + json + " > " + dir_ + "/out.txt"), 0);
  auto parsed = readJsonFile(json);
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_TRUE(parsed->at("agents").at("2").at("ate_rmse_m").is_number());
  EXPECT_EQ(run(tool + " --help > /dev/null"), 0);
  EXPECT_NE(run(tool + " --run " + dir_ + "/nowhere 2> " + dir_ + "/err.txt"), 0);
  std::ifstream err(dir_ + "/err.txt");
  std::string line;
  std::getline(err, line);
  EXPECT_NE(line.find("cvslam_eval: "), std::string::npos) << line;
  EXPECT_NE(run(tool + " --bogus 2> /dev/null"), 0);
  std::ofstream(dir_ + "/run/agent_2/trajectory.tum") << "0 1 2\n";
  EXPECT_NE(run(tool + " --run " + dir_ + "/run 2> /dev/null > /dev/null"), 0);
}

TEST_F(RunEvaluation, PlotScriptWritesFigures) {
  if (run("/usr/bin/python3 -c 'import matplotlib, numpy' 2> /dev/null") != 0)
    CVSLAM_SKIP_UNLESS_CI() << "/usr/bin/python3 lacks matplotlib or numpy (scripts/setup.sh)";
  const std::string script = test::sourceDir() + "/scripts/plot_run.py";
  ASSERT_EQ(run("/usr/bin/python3 " + script + " " + dir_ + "/run > /dev/null"), 0);
  for (const char* png :
       {"agent_1_position.png", "agent_1_errors.png", "agent_2_position.png", "trajectories.png",
        "landmark_uncertainty.png", "state_size.png", "nees.png"}) {
    const std::string path = dir_ + "/run/plots/" + png;
    ASSERT_TRUE(fs::exists(path)) << png;
    EXPECT_GT(fs::file_size(path), 10000u) << png;
  }
  EXPECT_NE(run("/usr/bin/python3 " + script + " " + dir_ + "/nowhere 2> /dev/null"), 0);
}

}  // namespace
}  // namespace cvslam
