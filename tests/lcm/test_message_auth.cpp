// Authenticated cooperation messages (transport/…/message_auth.h, docs/transport.md): a signed
// message verifies; any changed byte, a wrong key or another channel is forged; a replayed
// counter is refused, a reordered one within the window is not; over a real bus, forged,
// replayed and unsigned messages on signed channels are dropped and counted, while sensor
// channels stay unsigned. Bus tests on LCM port 27870.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/message_auth.h"
#include "cvslam/lcm/message_types.h"
#include "sample_messages.h"

namespace cvslam::transport {
namespace {

using namespace std::chrono_literals;

TeamKey key(char fill) {
  TeamKey k;
  k.bytes.assign(32, static_cast<uint8_t>(fill));
  return k;
}

TEST(MessageAuth, SignedMessagesVerifyAndAnyChangeIsForged) {
  cvslam::agent_summary_t m = testing::sample<cvslam::agent_summary_t>();
  auto encoding = encodeMessage(m);
  ASSERT_TRUE(encoding.ok());
  MessageSigner signer(key('k'));
  const std::vector<uint8_t> sent = signer.sign("TEAM/SUMMARY", encoding->data(), encoding->size());
  ASSERT_EQ(sent.size(), encoding->size() + kAuthTrailerBytes);
  std::size_t payload = 0;
  uint64_t counter = 0;
  EXPECT_EQ(verifyTrailer(key('k'), "TEAM/SUMMARY", sent.data(), sent.size(), &payload, &counter),
            AuthVerdict::kAccepted);
  EXPECT_EQ(payload, encoding->size());
  EXPECT_EQ(verifyTrailer(key('x'), "TEAM/SUMMARY", sent.data(), sent.size(), &payload, &counter),
            AuthVerdict::kForged);
  EXPECT_EQ(verifyTrailer(key('k'), "UAV1/INDEX", sent.data(), sent.size(), &payload, &counter),
            AuthVerdict::kForged);
  EXPECT_EQ(verifyTrailer(key('k'), "TEAM/SUMMARY", encoding->data(), encoding->size(), &payload,
                          &counter),
            AuthVerdict::kUnsigned);
  // One flipped bit anywhere: payload, counter or tag → forged; in the marker → unsigned.
  for (std::size_t i = 0; i < sent.size(); ++i) {
    std::vector<uint8_t> flipped = sent;
    flipped[i] ^= 0x10;
    const AuthVerdict v =
        verifyTrailer(key('k'), "TEAM/SUMMARY", flipped.data(), flipped.size(), &payload, &counter);
    const bool marker = i >= encoding->size() && i < encoding->size() + 4;
    EXPECT_EQ(v, marker ? AuthVerdict::kUnsigned : AuthVerdict::kForged) << "byte " << i;
  }
  // Counters strictly increase, even within one clock tick.
  std::size_t p1 = 0, p2 = 0;
  uint64_t c1 = 0, c2 = 0;
  const auto a = signer.sign("TEAM/SUMMARY", encoding->data(), encoding->size());
  const auto b = signer.sign("TEAM/SUMMARY", encoding->data(), encoding->size());
  ASSERT_EQ(verifyTrailer(key('k'), "TEAM/SUMMARY", a.data(), a.size(), &p1, &c1),
            AuthVerdict::kAccepted);
  ASSERT_EQ(verifyTrailer(key('k'), "TEAM/SUMMARY", b.data(), b.size(), &p2, &c2),
            AuthVerdict::kAccepted);
  EXPECT_GT(c2, c1);
}

TEST(MessageAuth, ReplayWindowRefusesRepeatsAndTheTooOld) {
  ReplayWindow w;
  EXPECT_TRUE(w.accept(1000));
  EXPECT_FALSE(w.accept(1000));  // a repeat
  EXPECT_TRUE(w.accept(1005));
  EXPECT_TRUE(w.accept(1003));  // reordered, within the window
  EXPECT_FALSE(w.accept(1003));
  EXPECT_TRUE(w.accept(1000 + 200));
  EXPECT_FALSE(w.accept(1005));  // now older than the window
  EXPECT_TRUE(w.accept(1200 - 63));
  EXPECT_FALSE(w.accept(1200 - 64));
}

TEST(MessageAuth, KeyFilesAreCheckedAndANewlineIsNotPartOfTheKey) {
  const std::string dir = ::testing::TempDir();
  const std::string shortk = dir + "/short.key", good = dir + "/good.key", same = dir + "/same.key";
  std::ofstream(shortk) << "tooshort\n";
  std::ofstream(good) << "0123456789abcdef0123456789abcdef\n";
  std::ofstream(same) << "0123456789abcdef0123456789abcdef";
  EXPECT_FALSE(TeamKey::readFile(shortk).ok());
  EXPECT_FALSE(TeamKey::readFile(dir + "/missing.key").ok());
  auto a = TeamKey::readFile(good), b = TeamKey::readFile(same);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->bytes, b->bytes);
  EXPECT_EQ(a->bytes.size(), 32u);
}

TEST(MessageAuth, BusDropsAndCountsForgedReplayedAndUnsignedMessages) {
  const std::string url = "udpm://239.255.76.67:27870?ttl=0";
  auto team = std::make_shared<const TeamKey>(key('k'));
  auto make = [&](std::shared_ptr<const TeamKey> k) {
    BusOptions o;
    o.url = url;
    o.auth_key = std::move(k);
    auto bus = LcmBus::create(o);
    EXPECT_TRUE(bus.ok());
    return std::move(*bus);
  };
  auto receiver = make(team), member = make(team),
       attacker = make(std::make_shared<const TeamKey>(key('x'))), plain = make(nullptr);
  std::atomic<int> summaries{0}, imu{0};
  ASSERT_TRUE(receiver
                  ->subscribe<cvslam::agent_summary_t>(
                      "TEAM/SUMMARY", [&](const cvslam::agent_summary_t&) { ++summaries; })
                  .ok());
  ASSERT_TRUE(
      receiver->subscribe<cvslam::imu_t>("UAV1/IMU", [&](const cvslam::imu_t&) { ++imu; }).ok());
  ASSERT_TRUE(receiver->start().ok());
  // What a replayer captured: a member's signed bytes, as they went on the wire.
  cvslam::agent_summary_t m = testing::sample<cvslam::agent_summary_t>();
  auto encoding = encodeMessage(m);
  ASSERT_TRUE(encoding.ok());
  MessageSigner member_signer(key('k'));
  const auto captured = member_signer.sign("TEAM/SUMMARY", encoding->data(), encoding->size());
  ASSERT_TRUE(plain->publishRaw("TEAM/SUMMARY", captured.data(), captured.size()).ok());
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(member->publish("TEAM/SUMMARY", m).ok());    // accepted
    ASSERT_TRUE(attacker->publish("TEAM/SUMMARY", m).ok());  // forged
    ASSERT_TRUE(plain->publish("TEAM/SUMMARY", m).ok());     // unsigned
    ASSERT_TRUE(
        plain->publishRaw("TEAM/SUMMARY", captured.data(), captured.size()).ok());  // replayed
    std::vector<uint8_t> flipped = captured;
    flipped[30] ^= 1;
    ASSERT_TRUE(plain->publishRaw("TEAM/SUMMARY", flipped.data(), flipped.size()).ok());  // forged
    cvslam::imu_t s = testing::sample<cvslam::imu_t>();
    ASSERT_TRUE(plain->publish("UAV1/IMU", s).ok());  // sensor channels are not signed
  }
  for (int i = 0; i < 50 && (summaries < 6 || imu < 5); ++i) std::this_thread::sleep_for(20ms);
  std::this_thread::sleep_for(100ms);
  const ChannelCounters c = receiver->counters("TEAM/SUMMARY");
  EXPECT_EQ(summaries.load(), 6);  // the captured original once, and the member's five
  EXPECT_EQ(imu.load(), 5);
  EXPECT_EQ(c.forged, 10);
  EXPECT_EQ(c.replayed, 5);
  EXPECT_EQ(c.unsigned_msgs, 5);
  EXPECT_EQ(c.invalid, 20);
}

}  // namespace
}  // namespace cvslam::transport
