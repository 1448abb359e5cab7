// CrossUavMatchAudit (simrun/cross_uav_match_audit.h): twins in view, their feature index and
// descriptor, the precision and recall of fused pairs, and the crossings, on hand-made landmark
// sets.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "cvslam/simrun/cross_uav_match_audit.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam::simrun {
namespace {

constexpr int64_t kNow = 2'000'000;

StateLandmark landmark(int64_t id, uint32_t index, int64_t last_seen_us, uint8_t descriptor_fill) {
  StateLandmark l;
  l.id = id;
  l.index = index;
  l.last_seen_us = last_seen_us;
  l.descriptor.assign(128, descriptor_fill);
  return l;
}

CrossUavMatchAudit::Truth truthOf(const std::map<int64_t, Eigen::Vector3d>& where) {
  return [where](int64_t id, Eigen::Vector3d* p) {
    auto it = where.find(id);
    if (it == where.end()) return false;
    *p = it->second;
    return true;
  };
}

class CrossUavMatchAuditTest : public ::testing::Test {
 protected:
  // UAV1 observes 1 and 2 now; 3 was seen a frame earlier, 4 now but without truth.
  std::vector<StateLandmark> own{landmark(1, 7, kNow, 100), landmark(2, 8, kNow, 100),
                                 landmark(3, 9, kNow - 100'000, 100), landmark(4, 5, kNow, 100)};
  std::map<int64_t, Eigen::Vector3d> own_truth{
      {1, {0.0, 0.0, 0.0}}, {2, {5.0, 0.0, 0.0}}, {3, {9.0, 0.0, 0.0}}};
  // UAV2's state: 11 is 1's twin with its index and a close descriptor; 12 is 2's twin under
  // another index; 13 is 3's twin (3 not in view); 14 has no twin.
  std::vector<StateLandmark> peer{landmark(11, 7, 0, 110), landmark(12, 6, 0, 100),
                                  landmark(13, 9, 0, 100), landmark(14, 7, 0, 100)};
  std::map<int64_t, Eigen::Vector3d> peer_truth{{11, {0.05, 0.0, 0.0}},
                                                {12, {5.0, 0.08, 0.0}},
                                                {13, {9.0, 0.0, 0.0}},
                                                {14, {20.0, 0.0, 0.0}}};
};

TEST_F(CrossUavMatchAuditTest, CountsTwinsInViewWithTheirIndexAndDescriptor) {
  CrossUavMatchAudit audit;
  audit.observe(1, kNow, own, truthOf(own_truth), 2, peer, truthOf(peer_truth));
  const CrossUavMatchReport& r = audit.report();
  EXPECT_EQ(r.twin_observations, 2);   // 1–11 and 2–12; 3 is not in view, 4 has no truth
  EXPECT_EQ(r.twin_same_index, 1);     // 1–11
  EXPECT_EQ(r.twin_descriptor_ok, 1);  // |100 − 110| · √128 ≈ 113 ≤ 250
  EXPECT_EQ(r.distinct_twin_pairs, 2);
  EXPECT_EQ(r.fused, 0);
  EXPECT_DOUBLE_EQ(r.recall(), 0.0);

  // The same pairs seen again, and from the other UAV: observations add up, pairs do not.
  audit.observe(1, kNow, own, truthOf(own_truth), 2, peer, truthOf(peer_truth));
  for (StateLandmark& l : peer) l.last_seen_us = kNow;
  audit.observe(2, kNow, peer, truthOf(peer_truth), 1, own, truthOf(own_truth));
  EXPECT_EQ(audit.report().twin_observations, 2 + 2 + 3);  // 11–1, 12–2, 13–3
  EXPECT_EQ(audit.report().distinct_twin_pairs, 3);
}

TEST_F(CrossUavMatchAuditTest, ADistantDescriptorOrAFarPointIsNoMatchOpportunity) {
  CrossUavMatchAuditOptions o;
  o.max_descriptor_distance = 100.0;  // below 113
  o.twin_radius_m = 0.06;             // 12 is 0.08 m from 2
  CrossUavMatchAudit audit(o);
  audit.observe(1, kNow, own, truthOf(own_truth), 2, peer, truthOf(peer_truth));
  EXPECT_EQ(audit.report().twin_observations, 1);
  EXPECT_EQ(audit.report().twin_same_index, 1);
  EXPECT_EQ(audit.report().twin_descriptor_ok, 0);
}

TEST_F(CrossUavMatchAuditTest, FusedPairsAreRightOnlyWhenTheyAreTwins) {
  CrossUavMatchAudit audit;
  audit.observe(1, kNow, own, truthOf(own_truth), 2, peer, truthOf(peer_truth));
  audit.fused(1, 1, truthOf(own_truth), 2, 11, truthOf(peer_truth));  // right
  audit.fused(2, 11, truthOf(peer_truth), 1, 1, truthOf(own_truth));  // its both-ways return
  audit.fused(1, 2, truthOf(own_truth), 2, 13, truthOf(peer_truth));  // 4 m apart: wrong
  audit.fused(1, 4, truthOf(own_truth), 2, 11, truthOf(peer_truth));  // no truth for 4
  audit.fused(1, 1, truthOf(own_truth), 2, -1, truthOf(peer_truth));  // sender's id unknown
  const CrossUavMatchReport& r = audit.report();
  EXPECT_EQ(r.fused, 5);
  EXPECT_EQ(r.fused_right, 2);
  EXPECT_EQ(r.fused_unknown, 2);
  EXPECT_DOUBLE_EQ(r.precision(), 2.0 / 3.0);
  EXPECT_EQ(r.distinct_twin_pairs_fused, 1);  // 1–11, from both sides
  EXPECT_DOUBLE_EQ(r.recall(), 0.5);          // of 1–11 and 2–12

  // A right pair that was never counted in view still counts as a twin pair found.
  audit.fused(1, 3, truthOf(own_truth), 2, 13, truthOf(peer_truth));
  EXPECT_EQ(audit.report().distinct_twin_pairs, 3);
  EXPECT_DOUBLE_EQ(audit.report().recall(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(audit.json()["precision"].get<double>(), 0.75) << audit.json().dump();
}

TEST_F(CrossUavMatchAuditTest, CrossingsAreSplitByGapsAndFusedOnlyByARightPairInTime) {
  CrossUavMatchAuditOptions o;
  o.crossing_gap_s = 2.0;
  CrossUavMatchAudit audit(o);
  const auto at = [&](int64_t t_us) {
    for (StateLandmark& l : own) l.last_seen_us = t_us;
    audit.observe(1, t_us, own, truthOf(own_truth), 2, peer, truthOf(peer_truth));
  };
  // First crossing: 10.0–11.0 s (gaps of 0.5 s); second: from 20 s (9 s later).
  for (int64_t t : {10'000'000, 10'500'000, 11'000'000}) at(t);
  at(20'000'000);
  EXPECT_EQ(audit.report().crossings, 2);
  // A right pair fused 1.5 s after the first crossing's last frame (the exchange's latency)
  // belongs to it; a wrong pair in the second does not fuse it; a right pair without a time
  // is attributed to none.
  audit.fused(1, 1, truthOf(own_truth), 2, 11, truthOf(peer_truth), 12'500'000);
  audit.fused(2, 11, truthOf(peer_truth), 1, 1, truthOf(own_truth), 12'500'000);
  audit.fused(1, 2, truthOf(own_truth), 2, 13, truthOf(peer_truth), 20'000'000);
  audit.fused(1, 1, truthOf(own_truth), 2, 11, truthOf(peer_truth));
  EXPECT_EQ(audit.report().crossings_fused, 1);
  const std::vector<Crossing> c = audit.crossings();
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].start_us, 10'000'000);
  EXPECT_EQ(c[0].end_us, 11'000'000);
  EXPECT_EQ(c[0].frames, 3);
  EXPECT_EQ(c[0].fused_right, 2);  // both directions of the exchange
  EXPECT_EQ(c[1].fused_right, 0);
  // Fused 3 s after the second crossing's last frame: beyond the gap, no crossing.
  audit.fused(1, 3, truthOf(own_truth), 2, 13, truthOf(peer_truth), 23'000'000);
  EXPECT_EQ(audit.report().crossings_fused, 1);
  const Json j = audit.json();
  ASSERT_EQ(j["crossings"].size(), 2u) << j.dump();
  EXPECT_EQ(j["crossings"][0]["uavs"][1].get<int>(), 2);
  EXPECT_DOUBLE_EQ(j["crossings"][1]["start_s"].get<double>(), 20.0);
  EXPECT_EQ(j["crossings_fused"].get<long>(), 1);
}

TEST_F(CrossUavMatchAuditTest, ACrossingNeedsGroundThePeerMappedNotATwin) {
  CrossUavMatchAuditOptions o;
  o.crossing_radius_m = 1.0;
  CrossUavMatchAudit audit(o);
  const std::vector<StateLandmark> seen{landmark(5, 7, kNow, 100)};
  // 0.5 m from the peer's 14: over its map, but no twin (0.1 m).
  audit.observe(1, kNow, seen, truthOf({{5, {20.5, 0.0, 0.0}}}), 2, peer, truthOf(peer_truth));
  EXPECT_EQ(audit.report().twin_observations, 0);
  EXPECT_EQ(audit.report().crossings, 1);
  // 2 m from it, 5 s later: no crossing.
  const std::vector<StateLandmark> later{landmark(5, 7, kNow + 5'000'000, 100)};
  audit.observe(1, kNow + 5'000'000, later, truthOf({{5, {22.0, 0.0, 0.0}}}), 2, peer,
                truthOf(peer_truth));
  EXPECT_EQ(audit.report().crossings, 1);
  EXPECT_EQ(audit.report().crossings_fused, 0);
}

TEST(CrossUavMatchReport, PrecisionIsOneAndRecallZeroWhenNothingHappened) {
  CrossUavMatchReport r;
  EXPECT_DOUBLE_EQ(r.precision(), 1.0);
  EXPECT_DOUBLE_EQ(r.recall(), 0.0);
}

}  // namespace
}  // namespace cvslam::simrun
