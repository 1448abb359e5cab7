// cvslam_lcm_stats as a process: counts what this process publishes on its own port,
// including a deliberate sequence gap and a foreign message, and writes the JSON.

#include <gtest/gtest.h>

#include "cvslam/io/json_file.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/message_types.h"
#include "euroc_test_folder.h"
#include "process_util.h"

namespace cvslam {
namespace {

TEST(LcmStatsProcess, CountsRatesAndGaps) {
  test::TempFolder tmp;
  const std::string url = "udpm://239.255.76.67:27767?ttl=0";
  test::Child stats(
      {CVSLAM_LCM_STATS_EXE, "--lcm-url", url, "--duration", "2.5", "--json", tmp / "s.json"},
      tmp / "stats");
  ASSERT_TRUE(stats.started());
  transport::BusOptions o;
  o.url = url;
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  // Publish once the tool says it listens (an event, not a sleep).
  for (int i = 0; i < 100 && stats.err().find("listening on") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_NE(stats.err().find("listening on"), std::string::npos) << stats.err();
  const auto first_sent = std::chrono::steady_clock::now();
  // 30 IMU messages numbered 0..19 and 25..34: 5 missing.
  for (int64_t seq = 0; seq < 35; ++seq) {
    if (seq >= 20 && seq < 25) continue;
    cvslam::imu_t m{};
    m.header.utime = seq * 5000;
    m.header.seq = seq;
    m.header.agent_id = -1;
    auto bytes = transport::encodeMessage(m);
    ASSERT_TRUE(bytes.ok());
    ASSERT_TRUE((*bus)->publishRaw("UAV1/IMU", bytes->data(), bytes->size()).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const double sent_span =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - first_sent).count();
  const std::vector<uint8_t> junk(40, 7);
  ASSERT_TRUE((*bus)->publishRaw("SOMETHING_ELSE", junk.data(), junk.size()).ok());
  EXPECT_EQ(stats.wait(std::chrono::seconds(10)), 1) << stats.err();  // 1: gaps seen
  EXPECT_NE(stats.out().find("UAV1/IMU"), std::string::npos) << stats.out();
  auto json = readJsonFile(tmp / "s.json");
  ASSERT_TRUE(json.ok()) << json.status().message();
  const Json& channels = json->at("channels");
  ASSERT_TRUE(channels.contains("UAV1/IMU"));
  const Json& imu = channels.at("UAV1/IMU");
  EXPECT_EQ(imu.at("messages").get<double>(), 30);
  EXPECT_EQ(imu.at("seq_gaps").get<double>(), 5);
  EXPECT_EQ(imu.at("type").get<std::string>(), "imu_t");
  // The rate is the messages over the span they arrived in, and that span is the one they were
  // sent in (they left at least 10 ms apart, so they cannot arrive in one burst).
  const double active = imu.at("active_s").get<double>();
  EXPECT_NEAR(imu.at("rate_hz").get<double>() * active, 29.0, 1e-9);
  EXPECT_LE(active, sent_span + 0.1);
  EXPECT_GE(active, 29 * 0.010);
  ASSERT_TRUE(channels.contains("SOMETHING_ELSE"));
  EXPECT_EQ(channels.at("SOMETHING_ELSE").at("no_header").get<double>(), 1);
  EXPECT_EQ(json->at("seq_gaps_total").get<double>(), 5);
  std::string out;
  EXPECT_EQ(test::run({CVSLAM_LCM_STATS_EXE, "--help"}, tmp / "h", &out), 0);
  EXPECT_NE(out.find("usage: cvslam_lcm_stats"), std::string::npos);
  std::string err;
  EXPECT_EQ(test::run({CVSLAM_LCM_STATS_EXE, "--lcm-url", url}, tmp / "e", nullptr, &err), 2);
  EXPECT_NE(err.find("--duration"), std::string::npos) << err;
}

}  // namespace
}  // namespace cvslam
