// The DC-link core (coop/dc_link_core.h) shared by cvslam_run --mode dc and cvslam_agent
// --mode dc: whatever order the peers' messages arrive in, and however late (before the frame
// that may apply them), the cooperation sees them in one order, so the trajectories and
// coop.csv are the same; our own broadcasts coming back are ignored; the report line.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "coop_team_fixture.h"
#include "cvslam/coop/dc_link_core.h"
#include "cvslam/io/run_record.h"
#include "euroc_test_folder.h"

namespace cvslam {
namespace {

struct LinkRun {
  std::string coop_csv[2];
  Eigen::VectorXd final_state[2];
  int64_t landmarks_fused = 0;
  std::string report;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Two UAVs linked through DcLinkCore. `scrambled`: every message is held until right before
/// its receiver's next cooperation step and handed over in reverse order, with an echo of the
/// receiver's own summary; otherwise each goes to the peer at once, in sending order.
LinkRun runLinked(const std::string& dir, bool scrambled) {
  LinkRun out;
  auto sc = sim::Scenario::fromString(cooptest::twoUavScenario(8.0, 3), "coop_pair.yaml");
  EXPECT_TRUE(sc.ok()) << sc.status().message();
  auto run = SimulatedTeamRun::create(*sc, VisualInertialSlamOptions{});
  EXPECT_TRUE(run.ok()) << run.status().message();
  if (!sc.ok() || !run.ok()) return out;
  coop::DcCooperationOptions options;
  options.true_ids = true;
  std::map<int, std::unique_ptr<coop::DcLinkCore>> cores;
  for (int id : {1, 2}) {
    cores[id] = std::make_unique<coop::DcLinkCore>(id, options, 1000 + id);
    EXPECT_TRUE(cores[id]->openLog(dir).ok());
  }
  std::map<int, std::vector<coop::CoopMessage>> held;  // receiver -> in arrival order
  Status s = (*run)->run([&](const SimulatedFrame& f) {
    coop::DcLinkCore& self = *cores[f.agent_id];
    std::vector<coop::CoopMessage>& mine = held[f.agent_id];
    for (auto m = mine.rbegin(); m != mine.rend(); ++m) self.receive(*m);
    mine.clear();
    coop::CoopOutbox box;
    if (Status st = self.afterFrame(f.sensing->lastObservations(), *f.mutable_slam, &box); !st.ok())
      return st;
    const int peer = 3 - f.agent_id;
    std::vector<std::pair<int, coop::CoopMessage>> sent;
    if (box.summary) {
      sent.emplace_back(peer, *box.summary);
      if (scrambled) sent.emplace_back(f.agent_id, *box.summary);  // multicast echo
    }
    if (box.index) sent.emplace_back(peer, *box.index);
    for (const coop::SharedRequest& r : box.requests) sent.emplace_back(r.to_agent, r);
    for (const coop::SharedLandmarks& l : box.shared) sent.emplace_back(l.to_agent, l);
    for (auto& [to, m] : sent) {
      if (scrambled) {
        held[to].push_back(m);
      } else {
        cores[to]->receive(m);
      }
    }
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  for (int i = 0; i < 2; ++i) {
    out.coop_csv[i] = slurp(agentDir(dir, i + 1) + "/coop.csv");
    out.final_state[i] = (*run)->slam(static_cast<std::size_t>(i)).vehicleState();
    out.landmarks_fused += cores[i + 1]->cooperation().statistics().landmarks_fused;
  }
  cores[1]->countSent("SUMMARY", 800);
  out.report = cores[1]->report(8.0);
  return out;
}

TEST(DcLinkCore, ArrivalOrderDoesNotChangeTheRun) {
  test::TempFolder tmp;
  const LinkRun in_order = runLinked(tmp / "in_order", false);
  const LinkRun scrambled = runLinked(tmp / "scrambled", true);
  EXPECT_GT(in_order.landmarks_fused, 0);  // the cooperation did something
  for (int i = 0; i < 2; ++i) {
    EXPECT_NE(in_order.coop_csv[i].find(",fused,"), std::string::npos) << in_order.coop_csv[i];
    EXPECT_EQ(scrambled.coop_csv[i], in_order.coop_csv[i]) << "UAV" << i + 1;
    ASSERT_EQ(scrambled.final_state[i].size(), in_order.final_state[i].size());
    EXPECT_EQ(scrambled.final_state[i], in_order.final_state[i]) << "UAV" << i + 1;
  }
  EXPECT_EQ(scrambled.landmarks_fused, in_order.landmarks_fused);
  // One line; the echo of UAV1's own summaries was not counted as a peer's message.
  const std::string& r = scrambled.report;
  EXPECT_EQ(r.find('\n'), std::string::npos) << r;
  EXPECT_EQ(r.rfind("UAV1 (adaptive CI) cooperation: peers 1, ", 0), 0u) << r;
  EXPECT_NE(r.find("rejected: invalid 0,"), std::string::npos) << r;
  EXPECT_NE(r.find("; 100 B/s ( SUMMARY 100 )"), std::string::npos) << r;
}

}  // namespace
}  // namespace cvslam
