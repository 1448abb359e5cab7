// LockstepTracker: epochs end at the team's frames; a participant acknowledges an epoch by
// reporting processed_utime ≥ the last utime sent to it; discovery needs one report first.

#include <gtest/gtest.h>

#include "cvslam/sensors/lockstep_tracker.h"

namespace cvslam {
namespace {

using T = SensorEventType;

TEST(LockstepTracker, NeedsAnAnnouncementBeforeTheFirstEpoch) {
  LockstepTracker t({1, 2}, {1, 2});
  EXPECT_FALSE(t.ready());
  EXPECT_EQ(t.waitingFor(), (std::vector<int>{1, 2}));
  t.onStatus(1, -1);
  EXPECT_EQ(t.waitingFor(), (std::vector<int>{2}));
  t.onStatus(2, -1);
  EXPECT_TRUE(t.ready());
  t.onStatus(7, 0);  // not a participant: ignored
  EXPECT_TRUE(t.ready());
}

TEST(LockstepTracker, EpochEndsAfterAllFramesOfOneInstant) {
  LockstepTracker t({1, 2}, {1, 2});
  t.onStatus(1, -1);
  t.onStatus(2, -1);
  // IMU and ground truth, then both agents' frames at 100 ms: one epoch.
  EXPECT_FALSE(t.startsNewEpoch(T::kImu, 100000));
  t.published(1, T::kImu, 100000, 100000);
  t.published(2, T::kImu, 100000, 100000);
  t.published(1, T::kGroundTruth, 100000, 100000);
  EXPECT_FALSE(t.startsNewEpoch(T::kStereoImage, 100000));
  t.published(1, T::kStereoImage, 100000, 100000);
  EXPECT_FALSE(t.startsNewEpoch(T::kStereoImage, 100000));  // agent 2's frame, same instant
  t.published(2, T::kStereoImage, 100000, 100000);
  EXPECT_TRUE(t.startsNewEpoch(T::kImu, 105000));
  EXPECT_TRUE(t.startsNewEpoch(T::kStereoImage, 200000));
  t.closeEpoch();
  EXPECT_EQ(t.epochsClosed(), 1);
  EXPECT_FALSE(t.ready());
  t.onStatus(1, 99999);  // not yet
  EXPECT_EQ(t.waitingFor(), (std::vector<int>{1, 2}));
  t.onStatus(1, 100000);
  t.onStatus(2, 100000);
  EXPECT_TRUE(t.ready());
  t.onStatus(2, 50000);  // a late, older report does not undo the acknowledgement
  EXPECT_TRUE(t.ready());
  EXPECT_FALSE(t.startsNewEpoch(T::kImu, 105000));  // the new epoch has no frame yet
}

TEST(LockstepTracker, PerAgentRequirementAndGroundStationRequirement) {
  // Agent 1 and the ground station (0) take part; agent 2 is replayed but not waited for.
  LockstepTracker t({1, 0}, {1, 2});
  t.onStatus(1, -1);
  t.onStatus(0, -1);
  t.published(1, T::kImu, 1000, 0);
  t.published(2, T::kImu, 7000, 0);  // agent 2's dataset runs on another clock
  t.published(1, T::kFeatures, 1000, 0);
  t.closeEpoch();
  t.onStatus(1, 1000);
  EXPECT_EQ(t.waitingFor(), (std::vector<int>{0}));
  t.onStatus(0, 6999);
  EXPECT_FALSE(t.ready());
  t.onStatus(0, 7000);  // the ground station must have seen everything sent
  EXPECT_TRUE(t.ready());
  // An epoch with nothing for agent 1 keeps its previous requirement.
  t.published(2, T::kFeatures, 9000, 100);
  t.closeEpoch();
  EXPECT_EQ(t.waitingFor(), (std::vector<int>{0}));
}

}  // namespace
}  // namespace cvslam
