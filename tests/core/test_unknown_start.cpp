// A scenario agent with `start: unknown` estimates in its own gravity-aligned frame (the origin
// and heading of its true start pose, scenario_agent.h): alone, its estimate in that frame is
// the known-start estimate moved by the same 4-dof transform, so its error is the same; the
// scenario refuses what would tell it the team's frame (a GPS).
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "coop_team_fixture.h"

namespace cvslam {
namespace {

/// RMS position error per agent of a whole single-mode run, in each agent's own frame.
std::map<int, double> ownFrameErrors(const sim::Scenario& scenario,
                                     std::map<int, Eigen::Vector3d>* first) {
  std::map<int, double> sum;
  std::map<int, int> n;
  auto run = SimulatedTeamRun::create(scenario, VisualInertialSlamOptions{});
  EXPECT_TRUE(run.ok()) << run.status().message();
  if (!run.ok()) return {};
  const Status s = (*run)->run([&](const SimulatedFrame& f) {
    const Eigen::Vector3d e = f.slam->vehicleState().head<3>() - f.truth->p_BinN;
    sum[f.agent_id] += e.squaredNorm();
    if (n[f.agent_id]++ == 0) (*first)[f.agent_id] = f.truth->p_BinN;
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  std::map<int, double> rms;
  for (const auto& [id, v] : sum) rms[id] = std::sqrt(v / n[id]);
  return rms;
}

TEST(UnknownStart, AnAgentAloneHasTheSameErrorInItsOwnFrame) {
  auto known = sim::Scenario::fromString(cooptest::twoUavScenario(6.0, 3), "coop_pair.yaml");
  ASSERT_TRUE(known.ok()) << known.status().message();
  sim::Scenario apart = *known;
  for (sim::AgentSpec& a : apart.agents) a.start_known = false;
  std::map<int, Eigen::Vector3d> first_known, first_apart;
  const std::map<int, double> e_known = ownFrameErrors(*known, &first_known);
  const std::map<int, double> e_apart = ownFrameErrors(apart, &first_apart);
  ASSERT_EQ(e_known.size(), 2u);
  ASSERT_EQ(e_apart.size(), 2u);
  for (const auto& [id, e] : e_known) {
    EXPECT_GT(e, 0.0);
    EXPECT_NEAR(e_apart.at(id), e, 1e-6 * (1.0 + e)) << "UAV" << id;
    // The frames do differ: the own frame's truth starts near its origin, the world's not.
    EXPECT_GT(first_known.at(id).head<2>().norm(), 5.0) << "UAV" << id;
    EXPECT_LT(first_apart.at(id).head<2>().norm(), 1.0) << "UAV" << id;
  }
}

TEST(UnknownStart, TheScenarioRefusesAGpsAndAnUnknownWord) {
  const std::string agent =
      "agents:\n  - id: 1\n    trajectory: {kind: circle, centre: [0, 0], radius: 20.0, "
      "altitude: 10.0, speed: 3.0}\n";
  auto gps = sim::Scenario::fromString(
      "duration: 5.0\n" + agent + "    start: unknown\n    gps: {}\n", "gps.yaml");
  ASSERT_FALSE(gps.ok());
  EXPECT_NE(gps.status().message().find("start"), std::string::npos) << gps.status().message();
  auto word =
      sim::Scenario::fromString("duration: 5.0\n" + agent + "    start: somewhere\n", "word.yaml");
  ASSERT_FALSE(word.ok());
  EXPECT_NE(word.status().message().find("known or unknown"), std::string::npos)
      << word.status().message();
}

}  // namespace
}  // namespace cvslam
