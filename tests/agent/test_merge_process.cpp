// Teams that start apart as real processes over loopback LCM (docs/merge.md): a restarted peer
// (a new process, a new boot id) loses its frame relation and is found again; a peer that never
// flies where the agent flew stays unmerged, quietly; malformed, non-finite and absurd place
// exchanges from a rogue peer are dropped and counted and never make a relation. Ports
// 27880–27882.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "agent_test_util.h"
#include "cvslam/lcm/coop_convert.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;
using test::slurp;

/// coop_pair flown for `duration` s; with `apart_m` > 0, UAV2's circle is moved that far east
/// (the two never see the same ground).
std::string pairFlight(const test::TempFolder& tmp, double duration, double apart_m) {
  std::string yaml = slurp(test::coopPair());
  const std::string d = "duration: 12.0";
  yaml.replace(yaml.find(d), d.size(), "duration: " + std::to_string(duration));
  if (apart_m > 0.0) {
    const std::string second = "start_angle_deg: -10.0}";
    const auto at = yaml.find(second);
    const std::string centre = "centre: [0.0, 0.0]";
    const auto c = yaml.rfind(centre, at);
    yaml.replace(c, centre.size(), "centre: [0.0, " + std::to_string(apart_m) + "]");
  }
  const std::string path = tmp / "pair.yaml";
  std::ofstream(path) << yaml;
  return path;
}

std::vector<std::string> agentApart(int id, const std::string& scenario, const std::string& url,
                                    const std::string& out) {
  std::vector<std::string> a = test::agentArgs(id, scenario, url, out, "dc");
  a.insert(a.end(), {"--starts", "unknown"});
  return a;
}

/// Lines of a text (a stderr flood shows here).
std::size_t textLines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

/// Agent `id`'s processed time, from its STATUS messages.
class ProcessedClock {
 public:
  ProcessedClock(transport::LcmBus& bus, int id) {
    bus.subscribe<cvslam::status_t>(
        "UAV" + std::to_string(id) + "/STATUS",
        [this](const cvslam::status_t& m) { t_us_ = m.processed_utime; });
  }
  int64_t us() const { return t_us_.load(); }

 private:
  std::atomic<int64_t> t_us_{-1};
};

std::unique_ptr<transport::LcmBus> loopbackBus(const std::string& url) {
  transport::BusOptions o;
  o.url = url;
  auto bus = transport::LcmBus::create(o);
  return bus.ok() ? std::move(*bus) : nullptr;
}

TEST(MergeProcess, ARestartedPeerLosesItsFrameAndIsFoundAgain) {
  test::TempFolder tmp;
  const std::string scenario = pairFlight(tmp, 30.0, 0.0);
  const std::string url = test::agentUrl(27880);
  auto bus = loopbackBus(url);
  ASSERT_NE(bus, nullptr);
  ProcessedClock clock(*bus, 1);
  ASSERT_TRUE(bus->start().ok());
  test::Child uav1(agentApart(1, scenario, url, tmp / "run"), tmp / "a1");
  auto uav2 = std::make_unique<test::Child>(agentApart(2, scenario, url, tmp / "before"),
                                            tmp / "a2_before");
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "2", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  // The pair merges after ≈ 6.5 s of flight (docs/merge.md); UAV2 is stopped at 14 s and a
  // new UAV2 process (a new boot id) joins in flight a second later.
  constexpr int64_t kStopUs = 14'000'000, kRestartUs = 15'000'000;
  auto waitUntil = [&](int64_t t_us) {
    for (int i = 0; i < 400 && clock.us() < t_us && !replay.exited(); ++i)
      std::this_thread::sleep_for(50ms);
  };
  waitUntil(kStopUs);
  ASSERT_FALSE(replay.exited()) << replay.err();
  ::kill(uav2->pid(), SIGTERM);
  EXPECT_EQ(uav2->wait(10s), 0) << uav2->err();
  waitUntil(kRestartUs);
  test::Child restarted(agentApart(2, scenario, url, tmp / "run"), tmp / "a2_after");
  EXPECT_EQ(replay.wait(60s), 0) << replay.err();
  EXPECT_EQ(uav1.wait(30s), 0) << uav1.err();
  EXPECT_EQ(restarted.wait(30s), 0) << restarted.err();

  const std::string out = uav1.out();
  EXPECT_EQ(test::countAfter(out, "peer restarts "), 1) << out;
  // Adopted before the restart, forgotten with it, adopted again after: an adopted relation is
  // only refined, so two adoptions need the forget in between.
  std::vector<double> adopted;
  for (const auto& r : test::csvRows(tmp / "run/agent_1/relations.csv"))
    if (r.size() > 2 && r[1] == "2" && r[2] == "adopted") adopted.push_back(std::stod(r[0]));
  ASSERT_EQ(adopted.size(), 2u) << slurp(tmp / "run/agent_1/relations.csv");
  EXPECT_LT(adopted[0], kStopUs * 1e-6);
  EXPECT_GT(adopted[1], kRestartUs * 1e-6);
  // The new UAV2 found UAV1's frame too, and reports its estimate in it.
  bool found = false;
  for (const auto& r : test::csvRows(tmp / "run/agent_2/relations.csv"))
    found = found || (r.size() > 2 && r[1] == "1" && r[2] == "adopted");
  EXPECT_TRUE(found) << restarted.out();
  const std::string team = slurp(tmp / "run/agent_2/trajectory_team.tum");
  EXPECT_EQ(team.rfind("# frame: agent_1", 0), 0u) << team.substr(0, 80);
  EXPECT_GT(test::poseCount(tmp / "run/agent_2/trajectory_team.tum"), 20u);
  // Started in flight, the new UAV2 estimates in its own frame, where its truth is recorded.
  const auto ate = test::ateOf(tmp / "run", tmp / "eval");
  ASSERT_EQ(ate.count(2), 1u);
  EXPECT_LT(ate.at(2), 1.0);
}

TEST(MergeProcess, APeerThatNeverOverlapsStaysUnmergedQuietly) {
  test::TempFolder tmp;
  const std::string scenario = pairFlight(tmp, 20.0, 200.0);
  const std::string url = test::agentUrl(27881);
  test::SummaryListener listener(url);
  ASSERT_TRUE(listener.ok());
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2})
    agents.push_back(std::make_unique<test::Child>(agentApart(id, scenario, url, tmp / "run"),
                                                   tmp / ("a" + std::to_string(id))));
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "4", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(60s), 0) << replay.err();
  for (auto& a : agents) {
    EXPECT_EQ(a->wait(30s), 0) << a->err();
    const std::string out = a->out();
    // They heard each other, sent place descriptors, and never found anything to verify.
    EXPECT_EQ(test::countAfter(out, "peers "), 1) << out;
    // (The report's "frames:" part names verifications and adoptions only when there were
    // verifications.)
    EXPECT_LE(test::countAfter(out, "relations adopted "), 0) << out;
    EXPECT_LE(test::countAfter(out, "verifications "), 0) << out;
    EXPECT_EQ(test::countAfter(out, "requests sent "), 0) << out;
    EXPECT_LE(textLines(a->err()), 3u) << a->err();
  }
  for (int id : {1, 2}) {
    const std::string dir = tmp / ("run/agent_" + std::to_string(id));
    EXPECT_FALSE(std::ifstream(dir + "/trajectory_team.tum").good());
    EXPECT_TRUE(test::csvRows(dir + "/relations.csv").empty());
    // Place descriptors go out at a bounded rate: one INDEX per place period (1 s).
    auto stats = readJsonFile(dir + "/stats.json");
    ASSERT_TRUE(stats.ok());
    const double index_rate = stats->at("bytes_sent_per_s").at("INDEX").get<double>();
    EXPECT_GT(index_rate, 0.0);
    EXPECT_LT(index_rate, 1000.0);
    // A summary every 0.5 s, the receive counters on one every 5 s (agent.counters_period_s).
    const auto [heard, counted] = listener.summaryCounts(id);
    EXPECT_GE(heard, 30) << "UAV" << id;
    EXPECT_GE(counted, 2) << "UAV" << id;
    EXPECT_LE(counted, heard / 8) << "UAV" << id;
  }
}

TEST(MergeProcess, MalformedAndAbsurdPlaceExchangesAreDroppedAndCounted) {
  test::TempFolder tmp;
  const std::string scenario = pairFlight(tmp, 12.0, 0.0);
  const std::string url = test::agentUrl(27882);
  test::Child agent(agentApart(1, scenario, url, tmp / "run"), tmp / "a1");
  auto bus = loopbackBus(url);
  ASSERT_NE(bus, nullptr);
  ProcessedClock clock(*bus, 1);
  // The agent's place descriptors: the rogue answers them with landmarks of those indices.
  std::mutex mutex;
  std::vector<uint32_t> place;
  ASSERT_TRUE(bus->subscribe<cvslam::feature_index_t>("UAV1/INDEX",
                                                      [&](const cvslam::feature_index_t& m) {
                                                        std::lock_guard<std::mutex> lock(mutex);
                                                        place.assign(m.index.begin(),
                                                                     m.index.end());
                                                      })
                  .ok());
  ASSERT_TRUE(bus->start().ok());
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "3", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  // A rogue peer (UAV 9) in a frame of its own: valid summaries; places with too many
  // indices; answers to the agent's places with non-finite, absurd, or random geometry.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> anywhere(-40.0, 40.0);
  int seq = 0, oversized = 0, absurd = 0, nan = 0, random_places = 0;
  while (!replay.exited()) {
    const int64_t t = clock.us();
    if (t > 0) {
      ASSERT_TRUE(test::publishRogueSummary(*bus, 9, seq, t, 40, true));
      coop::FeatureIndexList big;
      big.header = {9, seq, t};
      big.indices.resize(5000);
      for (std::size_t k = 0; k < big.indices.size(); ++k)
        big.indices[k] = static_cast<uint32_t>(k);
      auto bm = transport::toMessage(big);
      ASSERT_TRUE(bm.ok());
      ASSERT_TRUE(bus->publish("UAV9/INDEX", *bm).ok());
      ++oversized;
      std::vector<uint32_t> indices;
      {
        std::lock_guard<std::mutex> lock(mutex);
        indices = place;
      }
      if (indices.size() > 50) indices.resize(50);
      if (indices.size() >= 12) {
        coop::SharedLandmarks l;
        l.header = {9, seq, t};
        l.to_agent = 1;
        l.vehicle_cov_trace = 1.0;
        for (uint32_t index : indices)
          l.landmarks.push_back({index,
                                 Eigen::Vector3d(anywhere(rng), anywhere(rng), 10.0),
                                 0.01 * Eigen::Matrix3d::Identity(),
                                 {}});
        auto random = transport::toMessage(l);
        ASSERT_TRUE(random.ok());
        ASSERT_TRUE(bus->publish("UAV1/SHARED", *random).ok());
        ++random_places;
        l.header.seq = ++seq;
        l.landmarks[0].p_LinN.x() = 1e9;
        auto far = transport::toMessage(l);
        ASSERT_TRUE(far.ok());
        ASSERT_TRUE(bus->publish("UAV1/SHARED", *far).ok());
        ++absurd;
        far->position[1][2] = std::numeric_limits<double>::quiet_NaN();
        auto bytes = transport::encodeMessage(*far);
        if (bytes.ok() && bus->publishRaw("UAV1/SHARED", bytes->data(), bytes->size()).ok()) ++nan;
      }
      ++seq;
    }
    std::this_thread::sleep_for(150ms);
  }
  EXPECT_EQ(replay.wait(5s), 0) << replay.err();
  EXPECT_EQ(agent.wait(30s), 0) << agent.err();
  ASSERT_GT(oversized, 5);
  ASSERT_GT(random_places, 3) << "the agent sent too few places to answer";
  const std::string out = agent.out();
  // Oversized places and absurd answers: invalid in the cooperation; non-finite ones never got
  // past the transport (counted invalid on UAV1/SHARED).
  EXPECT_GE(test::countAfter(out, "rejected: invalid "), (oversized + absurd) / 2) << out;
  const auto inv = out.find(", invalid ");
  ASSERT_NE(inv, std::string::npos) << out;
  EXPECT_GE(std::stol(out.substr(inv + 10)), nan / 2) << out;
  // Random geometry is verified, fails, and is logged with why; nothing is adopted or fused.
  EXPECT_GE(test::countAfter(out, "verifications "), random_places / 2) << out;
  EXPECT_EQ(test::countAfter(out, "relations adopted "), 0) << out;
  EXPECT_NE(out.find("landmarks fused 0"), std::string::npos) << out;
  const auto rows = test::csvRows(tmp / "run/agent_1/relations.csv");
  ASSERT_FALSE(rows.empty());
  for (const auto& r : rows) {
    ASSERT_GT(r.size(), 2u);
    EXPECT_EQ(r[1], "9");
    EXPECT_EQ(r[2], "failed");
    EXPECT_FALSE(r.back().empty()) << "a failed verification says why";
  }
  EXPECT_LE(textLines(agent.err()), 3u) << agent.err();
  const auto ate = test::ateOf(tmp / "run", tmp / "eval");
  ASSERT_EQ(ate.count(1), 1u);
  EXPECT_LT(ate.at(1), 1.0);
}

}  // namespace
}  // namespace cvslam
