// The ground station's order of work (coop/cc_event_orderer.h): whatever the arrival order
// across agents, events come out by (time, agent, start before batch), each only once every
// other live agent has reached its time; a silent agent is no longer waited for; stale and
// reordered batches and unknown agents are refused on arrival.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

#include "cvslam/coop/cc_event_orderer.h"

namespace cvslam::coop {
namespace {

constexpr double kTimeout = 1.0;

CcEvent batch(int agent, int64_t t) {
  CcEvent e;
  e.kind = CcEvent::Kind::kBatch;
  e.agent_id = agent;
  e.t_us = t;
  e.batch.agent_id = agent;
  e.batch.t_us = t;
  return e;
}

CcEvent start(int agent, int64_t t) {
  CcEvent e = batch(agent, t);
  e.kind = CcEvent::Kind::kStart;
  return e;
}

using Key = std::tuple<int64_t, int, int>;

std::vector<Key> drain(CcEventOrderer& o, double now, bool flush = false) {
  std::vector<Key> out;
  CcEvent e;
  while (o.pop(now, flush, &e)) out.emplace_back(e.t_us, e.agent_id, static_cast<int>(e.kind));
  return out;
}

TEST(CcEventOrderer, AnyArrivalOrderGivesTheSameSequence) {
  std::vector<CcEvent> events;
  for (int a : {1, 2, 3}) events.push_back(start(a, 0));
  // Batches from t = 0: a start at t must not let another agent's batch at t pass the
  // starting agent's own batch at t.
  for (int64_t t = 0; t <= 1000; t += 100)
    for (int a : {1, 2, 3})
      if (!(a == 3 && t % 300 == 0)) events.push_back(batch(a, t));  // UAV3 skips some
  std::vector<Key> reference;
  for (unsigned seed = 0; seed < 20; ++seed) {
    // Each agent's own events stay in order (one sender), the agents interleave at random.
    std::mt19937 rng(seed);
    std::map<int, std::vector<CcEvent>> per_agent;
    for (const CcEvent& e : events) per_agent[e.agent_id].push_back(e);
    std::map<int, std::size_t> next;
    CcEventOrderer o({1, 2, 3}, kTimeout, 0.0);
    std::vector<Key> got;
    std::size_t left = events.size();
    while (left > 0) {
      const int a = 1 + static_cast<int>(rng() % 3);
      if (next[a] == per_agent[a].size()) continue;
      ASSERT_EQ(o.push(per_agent[a][next[a]++], 0.0), CcEventOrderer::Push::kQueued);
      --left;
      for (const Key& k : drain(o, 0.0)) got.push_back(k);
    }
    for (const Key& k : drain(o, 0.0, true)) got.push_back(k);
    ASSERT_EQ(got.size(), events.size());
    ASSERT_TRUE(std::is_sorted(got.begin(), got.end())) << "seed " << seed;
    if (seed == 0) reference = got;
    EXPECT_EQ(got, reference) << "seed " << seed;
  }
}

TEST(CcEventOrderer, WaitsForEveryLiveAgentAndNotForASilentOne) {
  CcEventOrderer o({1, 2}, kTimeout, 0.0);
  o.progress(2, -1, 0.0);  // UAV2 announced itself, no data yet
  ASSERT_EQ(o.push(batch(1, 100), 0.0), CcEventOrderer::Push::kQueued);
  EXPECT_TRUE(drain(o, 0.1).empty());  // UAV2 may still send something older
  EXPECT_EQ(o.processedUpTo(0.1), -1);
  o.progress(2, 100, 0.2);  // its STATUS: everything up to 100 µs sent
  EXPECT_EQ(drain(o, 0.2).size(), 1u);
  EXPECT_EQ(o.processedUpTo(0.2), 100);
  // UAV2 falls silent: after the timeout, UAV1 goes on alone.
  ASSERT_EQ(o.push(batch(1, 200), 0.9), CcEventOrderer::Push::kQueued);
  EXPECT_TRUE(drain(o, 0.9).empty());
  EXPECT_EQ(o.expire(1.3), std::vector<int>{2});
  EXPECT_FALSE(o.live(2, 1.3));
  EXPECT_EQ(drain(o, 1.3).size(), 1u);
  EXPECT_TRUE(o.expire(1.4).empty());  // reported once
  // Heard again: waited for again.
  o.progress(2, 250, 1.5);
  EXPECT_TRUE(o.live(2, 1.5));
  ASSERT_EQ(o.push(batch(1, 300), 1.5), CcEventOrderer::Push::kQueued);
  EXPECT_TRUE(drain(o, 1.5).empty());
}

TEST(CcEventOrderer, RefusesStaleReorderedAndUnknown) {
  CcEventOrderer o({1}, kTimeout, 0.0);
  EXPECT_EQ(o.push(batch(7, 100), 0.0), CcEventOrderer::Push::kUnknownAgent);
  EXPECT_FALSE(o.heardAll());
  ASSERT_EQ(o.push(batch(1, 200), 0.0), CcEventOrderer::Push::kQueued);
  EXPECT_TRUE(o.heardAll());
  EXPECT_EQ(o.push(batch(1, 200), 0.0), CcEventOrderer::Push::kStale);  // duplicate
  EXPECT_EQ(o.push(batch(1, 150), 0.0), CcEventOrderer::Push::kStale);  // reordered
  EXPECT_EQ(drain(o, 0.0).size(), 1u);
  EXPECT_EQ(o.push(batch(1, 100), 0.0), CcEventOrderer::Push::kStale);  // older than released
  // A restarted agent's batches no longer have to follow its old ones.
  o.restart(1);
  EXPECT_EQ(o.push(batch(1, 100), 0.0), CcEventOrderer::Push::kQueued);
}

TEST(CcEventOrderer, AStartComesBeforeABatchOfTheSameTime) {
  CcEventOrderer o({1}, kTimeout, 0.0);
  ASSERT_EQ(o.push(batch(1, 100), 0.0), CcEventOrderer::Push::kQueued);
  ASSERT_EQ(o.push(start(1, 100), 0.0), CcEventOrderer::Push::kQueued);
  const auto got = drain(o, 0.0);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(std::get<2>(got[0]), static_cast<int>(CcEvent::Kind::kStart));
}

TEST(CcEventOrderer, AStartDoesNotFinishTheBatchOfItsTime) {
  // UAV1's start estimate at 0 arrives, UAV2's start and batch at 0 follow before UAV1's batch
  // at 0 (as a loaded lockstep run interleaves them): UAV2's batch must wait for it.
  CcEventOrderer o({1, 2}, kTimeout, 0.0);
  ASSERT_EQ(o.push(start(1, 0), 0.0), CcEventOrderer::Push::kQueued);
  ASSERT_EQ(o.push(start(2, 0), 0.0), CcEventOrderer::Push::kQueued);
  ASSERT_EQ(o.push(batch(2, 0), 0.0), CcEventOrderer::Push::kQueued);
  // UAV1's start only: UAV1's batch at 0 may still come and precedes UAV2's start and batch.
  EXPECT_EQ(drain(o, 0.0), (std::vector<Key>{{0, 1, 0}}));
  ASSERT_EQ(o.push(batch(1, 0), 0.0), CcEventOrderer::Push::kQueued);
  EXPECT_EQ(drain(o, 0.0), (std::vector<Key>{{0, 1, 1}, {0, 2, 0}, {0, 2, 1}}));
}

}  // namespace
}  // namespace cvslam::coop
