// coop::PeerLinkMonitor: per-peer link quality from the cooperation messages' headers (lossy
// links, docs/transport.md) — received of expected by seq, late messages, restarts, age.
#include <gtest/gtest.h>

#include "cvslam/coop/peer_link_monitor.h"

namespace cvslam::coop {
namespace {

TEST(PeerLinkMonitor, CountsLossReorderingAndRestartsPerPeer) {
  PeerLinkMonitor m;
  using S = PeerLinkMonitor;
  for (int64_t seq : {0, 1, 2, 5, 4, 6})
    m.add({2, seq, 100000 * seq}, S::kSummary);  // 3 lost, 4 late
  for (int64_t seq : {0, 1, 2}) m.add({3, seq, 1000000}, S::kIndex);
  for (int64_t seq : {7, 8}) m.add({3, seq, 2000000}, S::kLandmarks);  // first seen at 7: no gap
  for (int64_t seq : {0, 1}) m.add({3, seq, 2500000}, S::kIndex);  // UAV 3 restarted: seq 0 again
  const auto links = m.links();
  ASSERT_EQ(links.size(), 2u);
  EXPECT_EQ(links.at(2).received, 6);
  EXPECT_EQ(links.at(2).missing, 1);  // seq 3
  EXPECT_EQ(links.at(2).expected(), 7);
  EXPECT_EQ(links.at(3).received, 7);
  EXPECT_EQ(links.at(3).missing, 0);
  EXPECT_EQ(links.at(3).newest_t_us, 2500000);
  EXPECT_EQ(m.text(3000000), "2: 6/7 age 2.40 s, 3: 7/7 age 0.50 s");
  EXPECT_EQ(PeerLinkMonitor().text(0), "none");
}

}  // namespace
}  // namespace cvslam::coop
