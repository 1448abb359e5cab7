// Authenticated cooperation against real agents (transport/…/message_auth.h, docs/transport.md):
// two DC agents share a team key while an attacker process sends summaries and landmarks as a
// UAV 9 (unsigned, and signed with a wrong key), a replayer sends captured genuine messages of
// UAV 2 again, and a bit-flipper sends them altered. With the key: 0 of them accepted, every one
// counted by kind. Without: the same attacker joins the team as a peer (the effect the
// defence removes). Ports 27840–27841.
#include <gtest/gtest.h>
#include <lcm/lcm.h>

#include <atomic>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "agent_test_util.h"
#include "cvslam/lcm/coop_convert.h"
#include "cvslam/lcm/header_peek.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

/// Raw bytes of the messages on one channel, as they went on the wire (trailer included).
class Capture {
 public:
  Capture(const std::string& url, const std::string& channel) : lcm_(lcm_create(url.c_str())) {
    lcm_subscribe(lcm_, channel.c_str(), &Capture::onMessage, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_handle_timeout(lcm_, 50);
    });
  }
  ~Capture() {
    stop_ = true;
    thread_.join();
    lcm_destroy(lcm_);
  }
  std::vector<std::vector<uint8_t>> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::move(messages_);
  }

 private:
  static void onMessage(const lcm_recv_buf_t* rbuf, const char*, void* self) {
    auto* c = static_cast<Capture*>(self);
    const auto* p = static_cast<const uint8_t*>(rbuf->data);
    std::lock_guard<std::mutex> lock(c->mutex_);
    c->messages_.emplace_back(p, p + rbuf->data_size);
  }
  lcm_t* lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::vector<uint8_t>> messages_;
};

struct AttackResult {
  std::string uav1_out, uav1_coop;
  int unsigned_sent = 0, forged_sent = 0, replayed_sent = 0;
};

AttackResult attack(const test::TempFolder& tmp, int port, bool with_key) {
  AttackResult result;
  const std::string url = test::agentUrl(port), key = tmp / "team.key", wrong = tmp / "wrong.key";
  std::ofstream(key) << "the team's secret key, 32 bytes!";
  std::ofstream(wrong) << "an attacker's guess at the key...";
  const std::string scenario = test::coopPair();
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2}) {
    auto args = test::agentArgs(id, scenario, url, tmp / "run", "dc");
    if (with_key) args.insert(args.end(), {"--auth-key", key});
    agents.push_back(std::make_unique<test::Child>(args, tmp / ("a" + std::to_string(id))));
  }
  auto bus = [&](const std::string& key_file) {
    transport::BusOptions o;
    o.url = url;
    if (!key_file.empty())
      o.auth_key =
          std::make_shared<const transport::TeamKey>(*transport::TeamKey::readFile(key_file));
    auto created = transport::LcmBus::create(o);
    EXPECT_TRUE(created.ok());
    return std::move(*created);
  };
  auto plain = bus(""), forger = bus(wrong);
  Capture genuine(url, "TEAM/SUMMARY");
  std::this_thread::sleep_for(500ms);
  test::Child replay({CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--rate",
                      "3", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  int k = 0;
  std::set<std::vector<uint8_t>> seen;
  while (!replay.exited()) {
    std::this_thread::sleep_for(200ms);
    // The attacker: a UAV 9 that says it is near and offers a landmark, unsigned and signed
    // with a wrong key.
    coop::CoopSummary s;
    s.header = {9, k, 1000000LL * k};
    s.boot_id = 99;
    s.num_features = 10;
    s.vehicle_cov_trace = 1.0;
    auto sm = transport::toMessage(s);
    coop::SharedLandmarks l;
    l.header = {9, k, 1000000LL * k};
    l.to_agent = 1;
    l.vehicle_cov_trace = 1.0;
    coop::SharedLandmark lm;
    lm.index = 3;
    lm.p_LinN = Eigen::Vector3d(5, 5, 0);
    lm.covariance = Eigen::Matrix3d::Identity();
    l.landmarks.push_back(lm);
    auto lmsg = transport::toMessage(l);
    if (!sm.ok() || !lmsg.ok()) continue;
    plain->publish("TEAM/SUMMARY", *sm);
    plain->publish("UAV1/SHARED", *lmsg);
    result.unsigned_sent += 2;
    forger->publish("TEAM/SUMMARY", *sm);
    forger->publish("UAV1/SHARED", *lmsg);
    result.forged_sent += 2;
    // The replayer and the bit-flipper: UAV 2's own summaries, again and altered.
    for (const auto& m : genuine.take()) {
      auto header = transport::peekHeader(m.data(), m.size());
      // Each genuine message once (the capture also hears what the replayer sends).
      if (!header || header->agent_id != 2 || !seen.insert(m).second) continue;
      plain->publishRaw("TEAM/SUMMARY", m.data(), m.size());
      ++result.replayed_sent;
      std::vector<uint8_t> flipped = m;
      flipped[40] ^= 0x01;  // inside ellipsoid_mean
      seen.insert(flipped);
      plain->publishRaw("TEAM/SUMMARY", flipped.data(), flipped.size());
      ++result.forged_sent;
    }
    ++k;
  }
  EXPECT_EQ(replay.wait(5s), 0) << replay.err();
  for (auto& a : agents) EXPECT_EQ(a->wait(30s), 0) << a->err();
  result.uav1_out = agents[0]->out();
  result.uav1_coop = test::slurp(tmp / "run/agent_1/coop.csv");
  return result;
}

TEST(AgentAuthProcess, WithTheTeamKeyNoAttackerMessageIsAcceptedAndEachIsCounted) {
  test::TempFolder tmp;
  const AttackResult r = attack(tmp, 27840, true);
  ASSERT_GT(r.replayed_sent, 5);
  ASSERT_GT(r.forged_sent, 10);
  // UAV 1 refused every one: by kind, exactly as many as were sent.
  EXPECT_EQ(test::countAfter(r.uav1_out, "refused: unsigned "), r.unsigned_sent) << r.uav1_out;
  EXPECT_EQ(test::countAfter(r.uav1_out, "forged "), r.forged_sent) << r.uav1_out;
  EXPECT_EQ(test::countAfter(r.uav1_out, "replayed "), r.replayed_sent) << r.uav1_out;
  // The attacker never became a peer; the genuine peer did, and they cooperated.
  EXPECT_EQ(r.uav1_coop.find(",peer_joined,9,"), std::string::npos) << r.uav1_coop;
  EXPECT_NE(r.uav1_coop.find(",peer_joined,2,"), std::string::npos) << r.uav1_coop;
  EXPECT_NE(r.uav1_out.find("peers 1,"), std::string::npos) << r.uav1_out;
}

TEST(AgentAuthProcess, WithoutTheKeyTheSameAttackerJoinsTheTeam) {
  test::TempFolder tmp;
  const AttackResult r = attack(tmp, 27841, false);
  // No authentication: the unsigned attacker is taken for a peer.
  EXPECT_NE(r.uav1_coop.find(",peer_joined,9,"), std::string::npos) << r.uav1_coop;
  EXPECT_NE(r.uav1_out.find("peers 2,"), std::string::npos) << r.uav1_out;
  EXPECT_EQ(r.uav1_out.find("authentication refused"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
