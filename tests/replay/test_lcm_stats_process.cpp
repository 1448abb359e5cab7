// cvslam_lcm_stats as a process: counts what this process publishes on its own port,
// including a deliberate sequence gap and a foreign message, and writes the JSON.

#include <gtest/gtest.h>

#include "cvslam/io/json.h"
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
  std::this_thread::sleep_for(std::chrono::milliseconds(800));  // stats subscribed
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
  const std::vector<uint8_t> junk(40, 7);
  ASSERT_TRUE((*bus)->publishRaw("SOMETHING_ELSE", junk.data(), junk.size()).ok());
  EXPECT_EQ(stats.wait(std::chrono::seconds(10)), 1) << stats.err();  // 1: gaps seen
  EXPECT_NE(stats.out().find("UAV1/IMU"), std::string::npos) << stats.out();
  auto json = Json::parseFile(tmp / "s.json");
  ASSERT_TRUE(json.ok()) << json.status().message();
  const Json* imu = json->find("channels")->find("UAV1/IMU");
  ASSERT_NE(imu, nullptr);
  EXPECT_EQ(imu->find("messages")->asNumber(), 30);
  EXPECT_EQ(imu->find("seq_gaps")->asNumber(), 5);
  EXPECT_EQ(imu->find("type")->asString(), "imu_t");
  EXPECT_GT(imu->find("rate_hz")->asNumber(), 20.0);  // ~ one per 10 ms plus publish time
  EXPECT_LT(imu->find("rate_hz")->asNumber(), 110.0);
  const Json* other = json->find("channels")->find("SOMETHING_ELSE");
  ASSERT_NE(other, nullptr);
  EXPECT_EQ(other->find("no_header")->asNumber(), 1);
  EXPECT_EQ(json->find("seq_gaps_total")->asNumber(), 5);
  std::string out;
  EXPECT_EQ(test::run({CVSLAM_LCM_STATS_EXE, "--help"}, tmp / "h", &out), 0);
  EXPECT_NE(out.find("usage: cvslam_lcm_stats"), std::string::npos);
  std::string err;
  EXPECT_EQ(test::run({CVSLAM_LCM_STATS_EXE, "--lcm-url", url}, tmp / "e", nullptr, &err), 2);
  EXPECT_NE(err.find("--duration"), std::string::npos) << err;
}

}  // namespace
}  // namespace cvslam
