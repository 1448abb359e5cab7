// A team whose starts are partly known (docs/merge.md): the agents started in the team's frame
// cooperate in it at once, and one started unknown is merged with them by place exchanges —
// nobody fuses its landmarks before the frame between them is adopted, since its SUMMARY says
// it estimates in a frame of its own.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "agent_test_util.h"
#include "cvslam/eval/team_evaluation.h"
#include "cvslam/io/run_reader.h"

namespace cvslam {
namespace {

using test::slurp;

/// Rows of a CSV whose columns may be text: the fields of each line after the header.
std::vector<std::vector<std::string>> csvRows(const std::string& path) {
  std::istringstream in(slurp(path));
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream fs(line);
    for (std::string f; std::getline(fs, f, ',');) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

/// When agent `self` first adopted a relation to `peer` (relations.csv); +inf if never.
double firstAdoption(const std::string& run, int self, int peer) {
  const std::string path = agentDir(run, self) + "/relations.csv";
  if (!std::ifstream(path).good()) return std::numeric_limits<double>::infinity();
  for (const auto& r : csvRows(path))  // t, peer, verdict, ...
    if (r.size() > 2 && std::stoi(r[1]) == peer && r[2] == "adopted") return std::stod(r[0]);
  return std::numeric_limits<double>::infinity();
}

TEST(MixedStarts, KnownAgentsShareTheFrameAndMergeTheUnknownOneByPlace) {
  test::TempFolder tmp;
  // team3_aerial with UAV2's start unknown (the shipped file has no relative paths).
  std::string yaml = slurp(test::sourceDir() + "/config/scenarios/team3_aerial.yaml");
  const std::string id2 = "  - id: 2\n";
  const auto at = yaml.find(id2);
  ASSERT_NE(at, std::string::npos);
  yaml.insert(at + id2.size(), "    start: unknown\n");
  const std::string scenario = tmp / "team3_uav2_apart.yaml";
  std::ofstream(scenario) << yaml;

  const std::string run = tmp / "run";
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", scenario, "--mode", "dc", "--out", run,
                       "--quiet"},
                      tmp / "cvslam_run", nullptr, &err),
            0)
      << err;
  auto info = readRunInfo(run);
  ASSERT_TRUE(info.ok()) << info.status().message();
  ASSERT_EQ(info->frames_in_world.size(), 1u);
  EXPECT_EQ(info->frames_in_world.count(2), 1u);

  // UAV2 found the team's frame and was right to.
  auto team = evaluateTeam(run, "");
  ASSERT_TRUE(team.ok()) << team.status().message();
  const TeamAgentEvaluation& uav2 = team->agents[1];
  ASSERT_EQ(uav2.id, 2);
  ASSERT_TRUE(uav2.relations && uav2.root);
  EXPECT_GE(uav2.relations->adopted, 1);
  EXPECT_EQ(uav2.relations->wrong_adopted, 0);
  EXPECT_EQ(*uav2.root, 1);

  for (int self : {1, 3}) {
    const int other_known = self == 1 ? 3 : 1;
    // Nothing to find between two agents in the given frame.
    EXPECT_EQ(firstAdoption(run, self, other_known), std::numeric_limits<double>::infinity());
    const double uav2_adopted = firstAdoption(run, self, 2);
    int fused_known = 0, fused_uav2 = 0;
    for (const auto& r : csvRows(agentDir(run, self) + "/coop.csv")) {  // t, event, peer, count, fused
      ASSERT_GE(r.size(), 5u);
      if (std::stoi(r[4]) == 0) continue;
      const double t = std::stod(r[0]);
      const int peer = std::stoi(r[2]);
      if (peer == other_known) ++fused_known;
      if (peer != 2) continue;
      ++fused_uav2;
      EXPECT_GE(t, uav2_adopted) << "UAV" << self << " fused UAV2's landmarks at " << t
                                 << " s, before it adopted UAV2's frame";
    }
    EXPECT_GT(fused_known, 0) << "UAV" << self << " and UAV" << other_known
                              << " cooperate in the given frame";
    // With the frames given, a known agent's team frame is its own: no trajectory_team.tum.
    EXPECT_FALSE(std::ifstream(agentDir(run, self) + "/trajectory_team.tum").good());
  }
}

}  // namespace
}  // namespace cvslam
