// Every run records its configuration (docs/run_format.md): cvslam_run writes
// agent_<id>/config_used.yaml (agent.yaml + the command-line overrides) and run.json (scenario,
// seed, duration, ...), and a run repeated from those files alone gives the same trajectories
// and cooperation logs.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "agent_test_util.h"
#include "cvslam/io/csv_table.h"
#include "cvslam/io/run_reader.h"

namespace cvslam {
namespace {

using test::slurp;

/// The YAML of a config_used.yaml without its first (comment) line, which names the source.
std::string yamlBody(const std::string& path) {
  const std::string text = slurp(path);
  const auto eol = text.find('\n');
  return eol == std::string::npos ? "" : text.substr(eol + 1);
}

TEST(RunConfig, RunRepeatedFromItsFolderGivesTheSameTrajectories) {
  test::TempFolder tmp;
  const std::string scenario = std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/coop_pair.yaml";
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--mode", "dc", "--filter", "nhinf",
                       "--passes", "2", "--ci", "fast", "--one-way", "--seed", "7", "--duration",
                       "10", "--out", tmp / "first", "--quiet"},
                      tmp / "first", nullptr, &err),
            0)
      << err;
  auto info = readRunInfo(tmp / "first");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->program, "cvslam_run");
  EXPECT_EQ(info->mode, "dc");
  EXPECT_EQ(info->filter, "nhinf");
  EXPECT_EQ(info->scenario, scenario);
  ASSERT_TRUE(info->seed.has_value());
  EXPECT_EQ(*info->seed, 7u);
  ASSERT_TRUE(info->duration_s.has_value());
  EXPECT_EQ(*info->duration_s, 10.0);
  EXPECT_EQ(info->sensing, "features");
  EXPECT_EQ(info->agents, (std::vector<int>{1, 2}));
  const std::string used = tmp / "first/agent_1/config_used.yaml";
  const std::string yaml = yamlBody(used);
  for (const char* recorded :
       {"type: nhinf", "observation_passes: 2", "ci_method: fast", "both_ways: false"})
    EXPECT_NE(yaml.find(recorded), std::string::npos) << recorded << " not in\n" << yaml;
  EXPECT_EQ(yamlBody(tmp / "first/agent_2/config_used.yaml"), yaml);

  // Again, from the folder alone: run.json and config_used.yaml, no other option.
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", info->scenario, "--mode", info->mode,
                       "--sensing", info->sensing, "--seed", std::to_string(*info->seed),
                       "--duration", std::to_string(*info->duration_s), "--config", used, "--out",
                       tmp / "again", "--quiet"},
                      tmp / "again", nullptr, &err),
            0)
      << err;
  for (const char* f : {"agent_1/trajectory.tum", "agent_2/trajectory.tum", "agent_1/states.csv",
                        "agent_1/coop.csv", "agent_2/coop.csv", "agent_2/events.csv"}) {
    const std::string first = slurp(tmp / (std::string("first/") + f));
    EXPECT_FALSE(first.empty()) << f;
    EXPECT_EQ(slurp(tmp / (std::string("again/") + f)), first) << f;
  }
  EXPECT_EQ(yamlBody(tmp / "again/agent_1/config_used.yaml"), yaml);
}

/// A UAV that plays a recorded IMU has no known biases: cvslam_run writes NaN as their truth
/// (no bias NEES against the simulator's zeros), a simulated IMU's true biases as numbers.
TEST(RunConfig, RecordedImuBiasesHaveNoTruth) {
  test::TempFolder tmp;
  const std::string scenario =
      std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/euroc_mh03_hall.yaml";
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--agents", "1,3", "--duration", "1",
                       "--out", tmp / "run", "--quiet"},
                      tmp / "run", nullptr, &err),
            0)
      << err;
  for (const auto& [agent, recorded] : {std::pair{"agent_1", false}, std::pair{"agent_3", true}}) {
    auto table = readCsvTable(tmp / (std::string("run/") + agent + "/biases.csv"));
    ASSERT_TRUE(table.ok()) << table.status().message();
    ASSERT_FALSE(table->rows.empty()) << agent;
    for (const char* col : {"bg_x", "true_bg_x", "true_ba_z"}) {
      const int c = table->column(col);
      ASSERT_GE(c, 0) << agent << " " << col;
      const bool truth = std::string(col).rfind("true_", 0) == 0;
      for (const std::vector<double>& row : table->rows)
        EXPECT_EQ(std::isfinite(row[static_cast<std::size_t>(c)]), !(truth && recorded))
            << agent << " " << col;
    }
  }
}

// The ideal EKF's diagnostic (cvslam_run --linearise-at-truth) marks its run as such, and is
// refused with images, whose landmarks have no true position when they are initialised.
TEST(RunConfig, LinearisationAtTheTruthIsRecordedAndRefusedWhereItCannotBeWhole) {
  test::TempFolder tmp;
  const std::string scenario = std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/coop_pair.yaml";
  std::string out, err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--duration", "2", "--out",
                       tmp / "ideal", "--quiet", "--linearise-at-truth"},
                      tmp / "ideal", nullptr, &err),
            0)
      << err;
  auto info = readRunInfo(tmp / "ideal");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_TRUE(info->linearised_at_truth);
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--duration", "2", "--out",
                       tmp / "own", "--quiet"},
                      tmp / "own", nullptr, &err),
            0)
      << err;
  info = readRunInfo(tmp / "own");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_FALSE(info->linearised_at_truth);
  EXPECT_NE(slurp(tmp / "ideal/agent_1/states.csv"), slurp(tmp / "own/agent_1/states.csv"));
  // In cc mode the ground station's models of each UAV take its truth too, in the additive chart
  // the ideal EKF needs: with the invariant chart's covariance and Jacobians at the truth, UAV1's
  // roll was 24σ off after 4 s.
  for (const bool ideal : {true, false}) {
    std::vector<std::string> args = {CVSLAM_RUN_EXE,
                                     "--scenario",
                                     scenario,
                                     "--mode",
                                     "cc",
                                     "--duration",
                                     "4",
                                     "--out",
                                     tmp / (ideal ? "cc_ideal" : "cc"),
                                     "--quiet"};
    if (ideal) args.push_back("--linearise-at-truth");
    ASSERT_EQ(test::run(args, tmp / (ideal ? "cc_ideal" : "cc"), nullptr, &err), 0) << err;
  }
  EXPECT_NE(slurp(tmp / "cc_ideal/ground_station/agent_2/states.csv"),
            slurp(tmp / "cc/ground_station/agent_2/states.csv"));
  for (const char* agent : {"agent_1", "agent_2"}) {
    const std::string dir = tmp / (std::string("cc_ideal/ground_station/") + agent);
    auto est = readCsvTable(dir + "/states.csv", {"t", "roll", "pitch", "var_roll", "var_pitch"});
    auto truth = readCsvTable(dir + "/truth.csv", {"t", "roll", "pitch"});
    ASSERT_TRUE(est.ok() && truth.ok()) << agent;
    ASSERT_FALSE(est->rows.empty() || truth->rows.empty()) << agent;
    const auto at = [](const CsvTable& t, const std::vector<double>& row, const std::string& c) {
      return row[static_cast<std::size_t>(t.column(c))];
    };
    const std::vector<double>& e = est->rows.back();
    const double t = at(*est, e, "t");
    const std::vector<double>* g = nullptr;
    for (const std::vector<double>& row : truth->rows)
      if (std::abs(at(*truth, row, "t") - t) < 1e-6) g = &row;
    ASSERT_NE(g, nullptr) << agent << ": no truth at " << t;
    for (const char* angle : {"roll", "pitch"}) {
      const double error = at(*est, e, angle) - at(*truth, *g, angle);
      const double sigma = std::sqrt(at(*est, e, std::string("var_") + angle));
      EXPECT_LT(std::abs(error), 3.0 * sigma) << agent << " " << angle << " at " << t << " s";
    }
  }
  EXPECT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--duration", "1", "--out",
                       tmp / "bad", "--linearise-at-truth", "--sensing", "images"},
                      tmp / "bad", &out, &err),
            2);
  EXPECT_EQ(err, "cvslam_run: --linearise-at-truth needs --sensing features\n");
}

}  // namespace
}  // namespace cvslam
