// Channel names (docs/architecture.md): built in one place, parsed back, regex-safe.

#include <gtest/gtest.h>

#include "cvslam/lcm/channels.h"

namespace cvslam::transport {
namespace {

TEST(Channels, BuildsTheDesignNames) {
  EXPECT_EQ(channels::imu(1), "UAV1/IMU");
  EXPECT_EQ(channels::stereo(2), "UAV2/STEREO");
  EXPECT_EQ(channels::features(3), "UAV3/FEATURES");
  EXPECT_EQ(channels::groundTruth(4), "UAV4/GT");
  EXPECT_EQ(channels::pose(5), "UAV5/POSE");
  EXPECT_EQ(channels::index(6), "UAV6/INDEX");
  EXPECT_EQ(channels::sharedRequest(7), "UAV7/SHARED_REQ");
  EXPECT_EQ(channels::shared(8), "UAV8/SHARED");
  EXPECT_EQ(channels::observations(9), "UAV9/OBS");
  EXPECT_EQ(channels::gsState(10), "UAV10/GS_STATE");
  EXPECT_EQ(channels::status(0), "UAV0/STATUS");
  EXPECT_EQ(channels::teamSummary(), "TEAM/SUMMARY");
  EXPECT_EQ(channels::gsMap(), "GS/MAP");
  EXPECT_EQ(channels::agentMap(3), "UAV3/MAP");
}

TEST(Channels, EveryNameParsesBackAndIsPlain) {
  const Stream all[] = {Stream::kImu,         Stream::kStereo, Stream::kFeatures,
                        Stream::kGroundTruth, Stream::kPose,   Stream::kIndex,
                        Stream::kSharedReq,   Stream::kShared, Stream::kObs,
                        Stream::kGsState,     Stream::kStatus, Stream::kMap,
                        Stream::kTeamSummary, Stream::kGsMap};
  for (Stream s : all) {
    for (int32_t id : {0, 1, 12, 2147483647}) {
      const std::string name = channelName(s, id);
      EXPECT_TRUE(isPlainChannelName(name)) << name;
      const auto parsed = parseChannel(name);
      ASSERT_TRUE(parsed.has_value()) << name;
      EXPECT_EQ(parsed->stream, s) << name;
      if (isPerAgent(s)) {
        EXPECT_EQ(parsed->agent_id, id) << name;
      } else {
        EXPECT_FALSE(parsed->agent_id.has_value()) << name;
      }
    }
  }
}

TEST(Channels, RejectsForeignAndNonCanonicalNames) {
  for (const char* bad :
       {"", "UAV/IMU", "UAV1", "UAV1/", "UAV1/imu", "UAV01/IMU", "UAV-1/IMU", "UAV+1/IMU",
        "UAV1x/IMU", "uav1/IMU", "UAV1/IMU/X", "UAV1/SUMMARY", "TEAM/IMU", "TEAM/MAP", "GS1/MAP",
        "GS/SUMMARY", "TEAM/SUMMARY2", "UAV2147483648/IMU", "UAV1/SHARED_REQX"}) {
    EXPECT_FALSE(parseChannel(bad).has_value()) << bad;
  }
}

TEST(Channels, PlainNamesExcludeRegexMetacharacters) {
  EXPECT_TRUE(isPlainChannelName("UAV1/SHARED_REQ"));
  for (const char* bad :
       {"", "UAV.*", "UAV1/IMU|", "A+B", "A?", "(A)", "[A]", "A\\B", "A^", "A$", "A{1}", "A B"}) {
    EXPECT_FALSE(isPlainChannelName(bad)) << bad;
  }
}

}  // namespace
}  // namespace cvslam::transport
