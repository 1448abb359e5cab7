// view::TeamView (common/view, docs/view.md): what cvslam_view gives its clients — decimated
// tracks, position NEES against the truth, latency and bytes/s, links, maps — as JSON deltas
// per client cursor, with memory bounded on long runs.
#include <gtest/gtest.h>

#include <cmath>

#include "cvslam/view/team_view.h"

namespace cvslam::view {
namespace {

ViewEstimate estimate(int id, double t, Eigen::Vector3d p, double var = 0.04) {
  ViewEstimate e;
  e.agent_id = id;
  e.t = t;
  e.p = p;
  e.P = Eigen::Matrix3d::Identity() * var;
  e.landmarks_active = 20;
  e.landmarks_archived = 5;
  return e;
}

TEST(TeamView, NeesIsThePositionErrorInTheCovarianceMetric) {
  TeamView view;
  view.addTruth(1, 1.0, Eigen::Vector3d(0, 0, 0));
  ViewEstimate e = estimate(1, 1.0, Eigen::Vector3d(0.2, 0.0, 0.0));
  e.P = Eigen::Vector3d(0.01, 0.04, 0.09).asDiagonal();
  view.addEstimate(e, 0.0);
  view.addEstimate(estimate(1, 5.0, Eigen::Vector3d(1, 0, 0)), 0.0);  // no truth near t = 5
  ViewCursor c;
  const Json d = view.delta(c, 0.0);
  const Json& s = d["agents"]["1"]["samples"];
  ASSERT_EQ(s.size(), 2u);
  EXPECT_NEAR(s[0][9].get<double>(), 0.2 * 0.2 / 0.01, 1e-3);  // eᵀP⁻¹e = 4
  EXPECT_TRUE(s[1][9].is_null());
  EXPECT_NEAR(s[0][7].get<double>(), std::sqrt(0.14), 1e-3);  // σ = sqrt(trace P)
}

TEST(TeamView, ClientsGetEachSampleOnceAndANewClientGetsEverything) {
  TeamViewOptions o;
  o.track_min_step_m = 0.5;
  TeamView view(o);
  // 0.1 m steps: one kept sample per 0.5 m (or per track_max_gap_s = 0.5 s of time).
  for (int k = 0; k <= 20; ++k)
    view.addEstimate(estimate(1, 0.01 * k, Eigen::Vector3d(0.1 * k, 0, 0)), 0);
  ViewCursor a;
  Json d = view.delta(a, 0);
  EXPECT_TRUE(d["reset"].get<bool>());
  EXPECT_EQ(d["agents"]["1"]["samples"].size(), 5u);  // x = 0, 0.5, 1.0, 1.5, 2.0
  EXPECT_EQ(d["agents"]["1"]["now"][1].get<double>(), 2.0);
  d = view.delta(a, 0);
  EXPECT_FALSE(d["reset"].get<bool>());
  EXPECT_TRUE(d["agents"]["1"]["samples"].empty());
  EXPECT_FALSE(d["agents"]["1"].contains("map"));  // unchanged since the last delta
  view.addEstimate(estimate(1, 0.3, Eigen::Vector3d(3, 0, 0)), 0);
  d = view.delta(a, 0);
  EXPECT_EQ(d["agents"]["1"]["samples_from"].get<int>(), 5);
  EXPECT_EQ(d["agents"]["1"]["samples"].size(), 1u);
  ViewCursor b;
  EXPECT_EQ(view.delta(b, 0)["agents"]["1"]["samples"].size(), 6u);
}

TEST(TeamView, StatusOfAgentsAndOfTheGroundStationReachesTheClient) {
  TeamView view;
  view.addEstimate(estimate(3, 1.0, Eigen::Vector3d::Zero()), 0.0);
  ViewCursor c;
  Json d = view.delta(c, 0.0);
  EXPECT_EQ(d["agents"]["3"]["health"], 0);
  EXPECT_FALSE(d.contains("gs_status"));
  // The ground station refused UAV3's batches; the agent repeats it in its own STATUS.
  view.setStatus(0, 1, "gs: vehicles 3; batches 10, refused 2: UAV3 propagation 2");
  view.setStatus(3, 1, "gs: fresh, adopted 10, own 2; gs refused my batches: propagation 2");
  d = view.delta(c, 0.0);
  EXPECT_EQ(d["gs_status"]["health"], 1);
  EXPECT_EQ(d["gs_status"]["message"], "gs: vehicles 3; batches 10, refused 2: UAV3 propagation 2");
  EXPECT_EQ(d["agents"]["3"]["health"], 1);
  EXPECT_NE(d["agents"]["3"]["status"].get<std::string>().find("refused my batches"),
            std::string::npos);
}

TEST(TeamView, LatencyAndBytesPerSecondComeFromArrivals) {
  TeamViewOptions o;
  o.rate_window_s = 2.0;
  TeamView view(o);
  view.addTraffic(1, 1000, 10.0);
  view.addTraffic(1, 3000, 11.0);
  view.addTraffic(1, 500, 7.0);  // older than the window at 11.5 s: dropped
  view.addFrameArrival(1, 2.0, 11.45);
  view.addEstimate(estimate(1, 2.0, Eigen::Vector3d::Zero()), 11.5);
  ViewCursor c;
  const Json s = view.delta(c, 11.5)["agents"]["1"]["samples"][0];
  EXPECT_NEAR(s[10].get<double>(), 50.0, 1e-6);    // latency [ms]
  EXPECT_NEAR(s[11].get<double>(), 2000.0, 1e-6);  // (1000 + 3000) B / 2 s
}

TEST(TeamView, LinksAreSentOnceAndMapsWhenTheyChange) {
  TeamView view;
  view.addEstimate(estimate(1, 1.0, Eigen::Vector3d::Zero()), 0);
  view.addLink(1, 2, 1.0, LinkKind::kRequest);
  view.addLink(2, 0, 1.1, LinkKind::kObservations);
  view.setMap(1, 1.0, {ViewLandmark{Eigen::Vector3f(1, 2, 3), 0.1f, true}});
  ViewCursor c;
  Json d = view.delta(c, 0);
  ASSERT_EQ(d["links"].size(), 2u);
  EXPECT_EQ(d["links"][0][3], "request");
  EXPECT_EQ(d["links"][1][2], 0);
  EXPECT_EQ(d["agents"]["1"]["map"]["points"][0][4], 1);
  d = view.delta(c, 0);
  EXPECT_TRUE(d["links"].empty());
  view.setMap(1, 2.0, {});
  EXPECT_TRUE(view.delta(c, 0)["agents"]["1"]["map"]["points"].empty());
}

TEST(TeamView, MemoryStaysBoundedAndClientsStartOverAfterThinning) {
  TeamViewOptions o;
  o.max_samples_per_uav = 100;
  o.max_links = 10;
  o.track_min_step_m = 0.0;
  TeamView view(o);
  ViewCursor c;
  for (int k = 0; k < 1000; ++k) {
    view.addEstimate(estimate(1, 0.1 * k, Eigen::Vector3d(k, 0, 0)), 0);
    view.addLink(1, 2, 0.1 * k, LinkKind::kLandmarks);
    if (k == 10) view.delta(c, 0);
  }
  const Json d = view.delta(c, 0);
  EXPECT_LE(d["agents"]["1"]["samples"].size(), 100u);
  EXPECT_EQ(d["agents"]["1"]["samples_from"].get<int>(), 0);              // thinned: from the start
  EXPECT_EQ(d["agents"]["1"]["samples"].back()[1].get<double>(), 999.0);  // newest kept
  EXPECT_EQ(d["links"].size(), 10u);                                      // the ten newest
}

TEST(TeamView, AgentsBeyondTheLimitAreCountedNotTracked) {
  TeamViewOptions o;
  o.max_agents = 2;
  TeamView view(o);
  for (int id : {1, 2, 3, -4}) view.addEstimate(estimate(id, 1.0, Eigen::Vector3d::Zero()), 0);
  view.countMalformed("UAV1/POSE");
  ViewCursor c;
  const Json d = view.delta(c, 0);
  EXPECT_EQ(d["agents"].size(), 2u);
  EXPECT_EQ(d["ignored_agents"], 2);
  EXPECT_EQ(d["malformed"], 1);
}

TEST(TeamView, OptionsAreReadAndChecked) {
  auto node = ConfigNode::fromString("link_hold_s: 2.5\nmax_agents: 0\n");
  ASSERT_TRUE(node.ok());
  TeamViewOptions o;
  const Status s = o.load(*node);
  EXPECT_EQ(o.link_hold_s, 2.5);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_agents"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace cvslam::view
