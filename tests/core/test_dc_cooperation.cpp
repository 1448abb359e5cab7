// DcCooperation (thesis §6.6.5): two feature-level UAVs with their own filters exchange the
// protocol's messages; UAV2 starts offset and must improve through UAV1's landmarks. Lost,
// duplicated, reordered, stale and malformed messages, both_ways, peer restart and timeout.

#include "cvslam/coop/dc_cooperation.h"

#include <gtest/gtest.h>

#include <deque>
#include <map>
#include <memory>
#include <random>

#include "coop_team_fixture.h"
#include "cvslam/io/config_node.h"

namespace cvslam {
namespace {

using cooptest::Envelope;
using cooptest::runTeam;
using cooptest::TeamOptions;
using cooptest::TeamResult;

constexpr double kDuration = 12.0;
constexpr uint64_t kSeed = 5;

const TeamResult& baseline() {
  static const TeamResult r = [] {
    TeamOptions o;
    o.cooperate = false;
    return runTeam(kDuration, kSeed, o);
  }();
  return r;
}

const TeamResult& cooperative() {
  static const TeamResult r = runTeam(kDuration, kSeed, TeamOptions{});
  return r;
}

TEST(DcCooperation, FusionImprovesTheWorseAgent) {
  const TeamResult& b = baseline();
  const TeamResult& c = cooperative();
  ASSERT_TRUE(b.ok && c.ok);
  EXPECT_GT(c.stats[0].summaries_received, 10);
  EXPECT_GT(c.stats[1].summaries_received, 10);
  const int64_t fused = c.stats[0].landmarks_fused + c.stats[1].landmarks_fused;
  EXPECT_GT(fused, 0);
  // UAV2 (offset start) gains: its landmark and vehicle errors drop clearly.
  EXPECT_LT(c.final_landmark_error[1], 0.7 * b.final_landmark_error[1])
      << "single " << b.final_landmark_error[1] << " dc " << c.final_landmark_error[1];
  EXPECT_LT(c.final_vehicle_error[1], 0.7 * b.final_vehicle_error[1])
      << "single " << b.final_vehicle_error[1] << " dc " << c.final_vehicle_error[1];
  // UAV1 does not get (much) worse.
  EXPECT_LT(c.final_vehicle_error[0], b.final_vehicle_error[0] + 0.1);
  EXPECT_EQ(c.stats[0].rejected_invalid + c.stats[1].rejected_invalid, 0);
  EXPECT_EQ(c.stats[0].rejected_duplicate + c.stats[1].rejected_duplicate, 0);
}

TEST(DcCooperation, FusedMatchesNameTheSenderLandmark) {
  // With true ids (feature level) a fused pair is one landmark: the receiver's id and the id
  // the sender recorded for that entry of its message must agree (the audit of
  // simrun/cross_uav_match_audit.h relies on it).
  const TeamResult& c = cooperative();
  ASSERT_TRUE(c.ok);
  std::size_t pairs = 0;
  for (int i = 0; i < 2; ++i) {
    int64_t fused = 0;
    for (const auto& [own, sender] : c.fused_pairs[i]) {
      EXPECT_EQ(own, sender);
      ++pairs;
      ++fused;
    }
    EXPECT_EQ(fused, c.stats[i].landmarks_fused);
  }
  EXPECT_GT(pairs, 0u);
}

TEST(DcCooperation, DuplicatedMessagesAreDroppedAndChangeNothing) {
  TeamOptions o;
  o.transport = [](int64_t, Envelope e) { return std::vector<Envelope>{e, e}; };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  const TeamResult& c = cooperative();
  EXPECT_GT(r.stats[0].rejected_duplicate, 10);
  EXPECT_GT(r.stats[1].rejected_duplicate, 10);
  EXPECT_EQ(r.stats[1].landmarks_fused, c.stats[1].landmarks_fused);
  EXPECT_DOUBLE_EQ(r.final_vehicle_error[1], c.final_vehicle_error[1]);
}

TEST(DcCooperation, LostSharedMessagesTimeOut) {
  TeamOptions o;
  o.transport = [](int64_t, Envelope e) {
    return e.shared ? std::vector<Envelope>{} : std::vector<Envelope>{e};
  };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  EXPECT_GT(r.stats[0].request_timeouts + r.stats[1].request_timeouts, 0);
  EXPECT_EQ(r.stats[0].landmarks_fused + r.stats[1].landmarks_fused, 0);
  // 30 % of all messages lost: the protocol still completes exchanges (both ways, so that
  // UAV2 also learns from the exchanges UAV1 starts). One loss pattern can cut every exchange
  // of a 12 s run; over eight patterns UAV2 fuses in most and gains on average.
  TeamOptions lossy;
  lossy.coop.both_ways = true;
  const int patterns = 8;
  int fused_runs = 0, timeouts = 0;
  double error_sum = 0.0;
  for (int pattern = 1; pattern <= patterns; ++pattern) {
    auto rng = std::make_shared<std::mt19937>(pattern);
    lossy.transport = [rng](int64_t, Envelope e) {
      return std::uniform_real_distribution<double>(0, 1)(*rng) < 0.3 ? std::vector<Envelope>{}
                                                                      : std::vector<Envelope>{e};
    };
    const TeamResult h = runTeam(kDuration, kSeed, lossy);
    ASSERT_TRUE(h.ok);
    fused_runs += h.stats[1].landmarks_fused > 0 ? 1 : 0;
    timeouts += static_cast<int>(h.stats[0].request_timeouts + h.stats[1].request_timeouts);
    error_sum += h.final_vehicle_error[1];
  }
  EXPECT_GE(fused_runs, 6) << "of " << patterns << ", mean error " << error_sum / patterns
                           << " single " << baseline().final_vehicle_error[1];
  EXPECT_GT(timeouts, 0);
  EXPECT_LT(error_sum / patterns, 0.7 * baseline().final_vehicle_error[1]);
}

TEST(DcCooperation, ALostAnswerIsAskedAgainAfterTheRoundTripTimeout) {
  auto first_answer_lost = std::make_shared<bool>(false);
  TeamOptions o;
  o.transport = [=](int64_t, Envelope e) {
    if (e.shared && !*first_answer_lost) {
      *first_answer_lost = true;
      return std::vector<Envelope>{};
    }
    return std::vector<Envelope>{e};
  };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  ASSERT_TRUE(*first_answer_lost);
  // The requester of the lost answer gives up min_request_timeout_s after its request (at the
  // first frame past it), is free to ask again, and later exchanges complete.
  const double frame_s = 0.1;  // the fixture's camera rate (10 Hz)
  int timeouts = 0;
  for (const auto& events : r.events) {
    int64_t sent_us = -1;
    for (const coop::CoopEvent& e : events) {
      if (e.kind == coop::CoopEventKind::kRequestSent) sent_us = e.t_us;
      if (e.kind != coop::CoopEventKind::kRequestTimeout) continue;
      ++timeouts;
      ASSERT_GE(sent_us, 0);
      const double waited_s = 1e-6 * static_cast<double>(e.t_us - sent_us);
      EXPECT_GT(waited_s, o.coop.min_request_timeout_s);
      EXPECT_LE(waited_s, o.coop.min_request_timeout_s + frame_s + 1e-9);
    }
  }
  EXPECT_EQ(timeouts, 1);
  EXPECT_GT(r.stats[0].landmarks_fused + r.stats[1].landmarks_fused, 0);
}

TEST(DcCooperation, ReorderedMessagesAreDropped) {
  // Each sender's summaries are held back one and delivered after its next (swapped pairs).
  TeamOptions o;
  auto held = std::make_shared<std::map<int, Envelope>>();
  o.transport = [held](int64_t, Envelope e) {
    if (!e.summary) return std::vector<Envelope>{e};
    auto it = held->find(e.from);
    if (it == held->end()) {
      held->emplace(e.from, e);
      return std::vector<Envelope>{};
    }
    std::vector<Envelope> out{e, it->second};
    held->erase(it);
    return out;
  };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  // UAV1 sees UAV2's swapped pair in one frame and drops the older one. (UAV2 applies UAV1's
  // pair in two frames, the older first: messages of a frame are applied after it, so a swap
  // within one of UAV2's frame periods cannot reach UAV2 out of order.)
  EXPECT_GT(r.stats[0].rejected_reordered, 5);
  EXPECT_GT(r.stats[0].landmarks_fused + r.stats[1].landmarks_fused, 0);
}

TEST(DcCooperation, StaleMessagesAreDropped) {
  // Every message arrives 3 s late (> max_message_age_s = 2 s): nothing is applied.
  TeamOptions o;
  auto queue = std::make_shared<std::deque<std::pair<int64_t, Envelope>>>();
  o.transport = [queue](int64_t t, Envelope e) {
    queue->emplace_back(t, std::move(e));
    std::vector<Envelope> out;
    while (!queue->empty() && queue->front().first <= t - 3'000'000) {
      out.push_back(queue->front().second);
      queue->pop_front();
    }
    return out;
  };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  EXPECT_GT(r.stats[0].rejected_stale, 10);
  EXPECT_EQ(r.stats[0].summaries_received + r.stats[1].summaries_received, 0);
  EXPECT_EQ(r.stats[0].landmarks_fused + r.stats[1].landmarks_fused, 0);
}

TEST(DcCooperation, GateRejectsLandmarksOffsetBy50m) {
  TeamOptions o;
  o.transport = [](int64_t, Envelope e) {
    if (e.shared)
      for (auto& l : e.shared->landmarks) l.p_LinN.x() += 50.0;
    return std::vector<Envelope>{e};
  };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  EXPECT_GT(r.stats[0].rejected_gate + r.stats[1].rejected_gate, 0);
  EXPECT_EQ(r.stats[0].landmarks_fused + r.stats[1].landmarks_fused, 0);
  EXPECT_DOUBLE_EQ(r.final_vehicle_error[1], baseline().final_vehicle_error[1]);
}

// map_shared_landmarks: a UAV that has mapped none of the points it observes (no new landmarks
// allowed) is offered a peer's landmarks of those points (their true positions, 5 cm). It asks
// for them, maps the observed points they match, fuses them (independent provenance) and its
// vehicle position bound shrinks. Offset by 50 m, the same landmarks fail the gate and nothing
// is mapped.
struct MappedExchange {
  coop::DcCooperationStatistics stats;
  std::vector<coop::MappedPoint> mapped;
  double trace_before = 0.0, trace_after = 0.0;
  int landmarks_after = 0;
};

MappedExchange exchangeWithAnUnmappedUav(double offset_m) {
  MappedExchange out;
  VisualInertialSlamOptions options;
  options.slam.max_new_landmarks_per_frame = 0;
  std::unique_ptr<SimulatedTeamRun> run = cooptest::createPair(2.0, 21, options);
  if (run == nullptr) return out;
  coop::DcCooperation uav2(2, coop::DcCooperationOptions{}, 2001);
  int64_t seq = 0;
  int frame = 0;
  std::vector<uint32_t> requested;
  const Status s = run->run([&](const SimulatedFrame& f) {
    if (f.agent_id != 2) return Status::Ok();
    const StereoFrameObservations& obs = f.sensing->lastObservations();
    const int64_t before_us = f.t_us - 1;  // messages of an earlier epoch
    coop::CoopSummary summary;
    summary.header = {1, seq++, before_us};
    summary.boot_id = 1001;
    summary.num_features = 100;  // UAV1 observes more: UAV2 would index, UAV1 offers
    uav2.onSummary(summary);
    if (frame == 5) {  // UAV1 offers what UAV2 observes now
      coop::FeatureIndexList index;
      index.header = {1, seq++, before_us};
      index.true_ids = true;
      for (const StereoObservation& o : obs.observations) index.indices.push_back(o.index);
      uav2.onIndex(index);
    }
    if (frame == 6 && !requested.empty()) {  // and answers UAV2's request
      coop::SharedLandmarks shared;
      shared.header = {1, seq++, before_us};
      shared.to_agent = 2;
      shared.informed_by = {1};
      for (uint32_t index : requested) {
        Eigen::Vector3d p;
        if (!f.sensing->landmarkTruth(index, &p)) continue;
        p.x() += offset_m;
        shared.landmarks.push_back({index, p, 0.05 * 0.05 * Eigen::Matrix3d::Identity(), {}});
      }
      uav2.onShared(shared);
      out.trace_before = f.mutable_slam->vehicleCovariance().topLeftCorner<3, 3>().trace();
    }
    coop::CoopOutbox box;
    if (Status st = uav2.afterFrame(obs, *f.mutable_slam, &box); !st.ok()) return st;
    if (frame == 5 && !box.requests.empty()) requested = box.requests.front().indices;
    if (frame == 6) {
      out.trace_after = f.mutable_slam->vehicleCovariance().topLeftCorner<3, 3>().trace();
      out.landmarks_after = static_cast<int>(f.mutable_slam->stateLandmarks().size());
    }
    ++frame;
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(requested.empty()) << "UAV2 asked for none of the points it observes";
  out.stats = uav2.statistics();
  out.mapped = uav2.mappedPoints();
  return out;
}

TEST(DcCooperation, APeersLandmarksOfUnmappedObservedPointsAreMappedAndFused) {
  const MappedExchange r = exchangeWithAnUnmappedUav(0.0);
  EXPECT_GE(r.stats.landmarks_mapped, 3);
  EXPECT_EQ(r.stats.landmarks_fused, r.stats.landmarks_mapped);
  EXPECT_EQ(r.stats.fused_independent, 1);
  EXPECT_EQ(r.landmarks_after, r.stats.landmarks_mapped);  // nothing else is ever mapped
  for (const coop::MappedPoint& m : r.mapped) EXPECT_GE(m.local_id, 0);  // the true ids
  // The peer's 5 cm landmarks pin the vehicle: its position bound shrinks by more than half.
  EXPECT_LT(r.trace_after, 0.5 * r.trace_before)
      << "before " << r.trace_before << " after " << r.trace_after;
}

TEST(DcCooperation, APeersLandmarkFarFromTheObservedPointIsNotMapped) {
  const MappedExchange r = exchangeWithAnUnmappedUav(50.0);
  EXPECT_GT(r.stats.shared_not_in_state, 0);
  EXPECT_EQ(r.stats.landmarks_mapped, 0);
  EXPECT_EQ(r.stats.landmarks_fused, 0);
  EXPECT_EQ(r.landmarks_after, 0);
}

TEST(DcCooperation, BothWaysReturnsEstimates) {
  TeamOptions one_way;
  one_way.coop.both_ways = false;
  const TeamResult one = runTeam(kDuration, kSeed, one_way);
  TeamOptions o;
  o.coop.both_ways = true;
  const TeamResult r = runTeam(kDuration, kSeed, o);
  // Every answered request is followed by a return of the receiver's estimates ...
  EXPECT_GT(r.stats[0].shared_received, one.stats[0].shared_received);
  EXPECT_LT(r.final_vehicle_error[1], 0.7 * baseline().final_vehicle_error[1]);
  // ... which the accurate UAV1 declines by default (its vehicle bound would not shrink) ...
  EXPECT_GT(r.stats[0].skipped_no_gain, 0);
  // ... and fuses when told to fuse regardless.
  o.coop.require_vehicle_gain = false;
  const TeamResult all = runTeam(kDuration, kSeed, o);
  EXPECT_GT(all.stats[0].landmarks_fused, 0);
  EXPECT_GT(all.stats[1].landmarks_fused, 0);
}

TEST(DcCooperation, PeerRestartAndTimeout) {
  TeamOptions restart;
  restart.restart_at_us = 6'000'000;
  const TeamResult r = runTeam(kDuration, kSeed, restart);
  EXPECT_EQ(r.stats[0].peer_restarts, 1);
  bool fused_after = false;
  for (const coop::CoopEvent& e : r.events[0])
    if (e.t_us > 7'000'000 && e.kind == coop::CoopEventKind::kSharedSent) fused_after = true;
  for (const coop::CoopEvent& e : r.events[1])
    if (e.t_us > 7'000'000 && e.kind == coop::CoopEventKind::kFused && e.fused > 0)
      fused_after = true;
  EXPECT_TRUE(fused_after) << "the restarted agent rejoins the exchange";

  TeamOptions deaf;
  deaf.deaf_after_us = 4'000'000;  // both go silent at 4 s; timeout 5 s
  const TeamResult d = runTeam(kDuration, kSeed, deaf);
  EXPECT_EQ(d.stats[0].peer_timeouts, 1);
  EXPECT_EQ(d.stats[1].peer_timeouts, 1);
  EXPECT_EQ(d.stats[0].peers_known, 0);
}

// Estimated frames: a restarted peer (new boot id) estimates in a new frame, so its relation
// is forgotten and found again from new verifications (docs/merge.md).
TEST(DcCooperation, ARestartedPeerLosesItsFrameAndIsFoundAgain) {
  TeamOptions restart;
  restart.coop.frames_given = false;
  restart.restart_at_us = 12'000'000;
  const TeamResult r = runTeam(24.0, kSeed, restart);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.stats[0].peer_restarts, 1);
  // Adopted before the restart, forgotten with it, adopted again after it: an adopted relation
  // is only refined, so a second adoption needs the forget in between.
  EXPECT_EQ(r.stats[0].relations_adopted, 2);
  EXPECT_EQ(r.stats[1].relations_adopted, 1);  // the restarted agent's own count
  EXPECT_EQ(r.stats[0].relations_rejected, 0);
}

// A peer whose places never verify (its answers' geometry scrambled on the way) is asked for
// them less and less often: the wait doubles after each failure up to max_place_backoff_s,
// where without the back-off it would be asked every place period. Nothing is adopted.
TEST(DcCooperation, APeerWhosePlacesNeverVerifyIsAskedLessAndLess) {
  using Requests = std::map<int, std::vector<int64_t>>;  // requester -> when it asked
  auto fly = [](double max_backoff_s, Requests* requests) {
    TeamOptions o;
    o.coop.frames_given = false;
    o.coop.max_place_backoff_s = max_backoff_s;
    auto rng = std::make_shared<std::mt19937>(11);
    o.transport = [rng, requests](int64_t t_us, Envelope e) {
      if (e.request) (*requests)[e.from].push_back(t_us);
      if (e.shared) {
        std::uniform_real_distribution<double> off(-5.0, 5.0);
        for (coop::SharedLandmark& l : e.shared->landmarks)
          l.p_LinN += Eigen::Vector3d(off(*rng), off(*rng), off(*rng));
      }
      return std::vector<Envelope>{e};
    };
    return runTeam(24.0, kSeed, o);
  };
  Requests backed_off, every_period;
  const TeamResult r = fly(8.0, &backed_off);
  const TeamResult flat = fly(1.0, &every_period);
  ASSERT_TRUE(r.ok && flat.ok);
  for (const TeamResult* t : {&r, &flat})
    EXPECT_EQ(t->stats[0].relations_adopted + t->stats[1].relations_adopted, 0);
  EXPECT_GE(flat.stats[0].verifications_failed + flat.stats[1].verifications_failed, 10);
  // The agent that asks most: half as often or less with the back-off, its waits growing to
  // the cap (a request follows the first place descriptor after the wait: ≤ 8 s + 1 s).
  int asker = 1;
  for (const auto& [id, times] : every_period)
    if (times.size() > every_period[asker].size()) asker = id;
  const std::vector<int64_t>& t = backed_off[asker];
  ASSERT_GE(t.size(), 4u);
  EXPECT_GE(every_period[asker].size(), 2 * t.size())
      << t.size() << " vs " << every_period[asker].size();
  EXPECT_GE(t.back() - t[t.size() - 2], 4'000'000);
  for (std::size_t k = 1; k < t.size(); ++k) {
    EXPECT_GE(t[k] - t[k - 1], t[1] - t[0]) << "the waits do not shrink";
    EXPECT_LE(t[k] - t[k - 1], 9'300'000);
  }
}

TEST(DcCooperation, MalformedMessagesAreRejectedAndCounted) {
  coop::DcCooperation c(1, coop::DcCooperationOptions{}, 7);
  coop::SharedLandmarks s;
  s.header = {2, 0, 1000};
  s.to_agent = 1;
  s.vehicle_cov_trace = 0.1;
  s.landmarks.push_back({5, {1, 2, 3}, 0.01 * Eigen::Matrix3d::Identity(), {}});
  EXPECT_TRUE(c.onShared(s));
  auto bad = [&](auto mutate) {
    coop::SharedLandmarks b = s;
    mutate(b);
    return c.onShared(b);
  };
  EXPECT_FALSE(bad([](auto& b) { b.landmarks[0].p_LinN.x() = NAN; }));
  EXPECT_FALSE(bad([](auto& b) { b.landmarks[0].p_LinN.x() = 1e7; }));
  EXPECT_FALSE(bad([](auto& b) { b.landmarks[0].covariance(0, 0) = -1.0; }));
  EXPECT_FALSE(bad([](auto& b) { b.landmarks[0].covariance *= 1e7; }));
  EXPECT_FALSE(bad([](auto& b) { b.landmarks[0].covariance(0, 1) = 0.5; }));  // asymmetric
  EXPECT_FALSE(bad([](auto& b) { b.vehicle_cov_trace = INFINITY; }));
  EXPECT_FALSE(bad([](auto& b) { b.landmarks.resize(1000, b.landmarks[0]); }));
  EXPECT_FALSE(bad([](auto& b) { b.header.agent_id = 0; }));
  EXPECT_EQ(c.statistics().rejected_invalid, 8);
  EXPECT_FALSE(bad([](auto& b) { b.to_agent = 3; }));
  EXPECT_FALSE(bad([](auto& b) { b.header.agent_id = 1; }));
  EXPECT_EQ(c.statistics().rejected_not_for_me, 2);
  coop::CoopSummary sum;
  sum.header = {2, 0, 0};
  sum.std = {1, 1, -1};
  EXPECT_FALSE(c.onSummary(sum));
  coop::FeatureIndexList idx;
  idx.header = {2, 0, 0};
  idx.indices.resize(5000);
  EXPECT_FALSE(c.onIndex(idx));
  EXPECT_EQ(c.statistics().rejected_invalid, 10);
}

// A flood of summaries from forged agent ids is bounded by max_peers; real peers keep working.
TEST(DcCooperation, ForgedPeerFloodIsBounded) {
  auto sc = sim::Scenario::fromString(cooptest::twoUavScenario(1.0, kSeed), "pair.yaml");
  ASSERT_TRUE(sc.ok());
  auto run = SimulatedTeamRun::create(*sc, VisualInertialSlamOptions{});
  ASSERT_TRUE(run.ok());
  coop::DcCooperationOptions o;
  o.max_peers = 4;
  coop::DcCooperation c(1, o, 7);
  Status s = (*run)->run([&](const SimulatedFrame& f) {
    if (f.agent_id != 1) return Status::Ok();
    for (int id = 2; id < 200; ++id) {
      coop::CoopSummary m;
      m.header = {id, f.t_us / 100000, f.t_us};
      m.boot_id = id;
      c.onSummary(m);
    }
    StereoFrameObservations frame;
    frame.t_us = f.t_us;
    coop::CoopOutbox box;
    return c.afterFrame(frame, *f.mutable_slam, &box);
  });
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(c.peers().size(), 4u);
  EXPECT_GT(c.statistics().rejected_too_many_peers, 1000);
}

// reask_period_s: no landmark is asked of the same peer twice within the period, the answers
// shrink, and the worse agent still gains from its peer.
TEST(DcCooperation, ALandmarkIsAskedAgainOnlyAfterTheReaskPeriod) {
  TeamOptions o;
  o.coop.reask_period_s = 1.0;
  std::map<std::pair<int, uint32_t>, int64_t> last_asked;  // (requester, index) -> t
  int64_t too_soon = 0, asked = 0, shared_landmarks = 0;
  o.transport = [&](int64_t t_us, Envelope e) {
    if (e.request)
      for (uint32_t index : e.request->indices) {
        ++asked;
        const auto key = std::make_pair(e.from, index);
        const auto it = last_asked.find(key);
        if (it != last_asked.end() && t_us - it->second < 1'000'000) ++too_soon;
        last_asked[key] = t_us;
      }
    if (e.shared) shared_landmarks += static_cast<int64_t>(e.shared->landmarks.size());
    return std::vector<Envelope>{e};
  };
  const TeamResult r = runTeam(kDuration, kSeed, o);
  ASSERT_TRUE(r.ok);
  EXPECT_GT(asked, 20);
  EXPECT_EQ(too_soon, 0);
  int64_t every_time = 0;
  TeamOptions count;
  count.coop.reask_period_s = 0.0;  // the thesis: asked at every exchange
  count.transport = [&](int64_t, Envelope e) {
    if (e.shared) every_time += static_cast<int64_t>(e.shared->landmarks.size());
    return std::vector<Envelope>{e};
  };
  ASSERT_TRUE(runTeam(kDuration, kSeed, count).ok);
  EXPECT_LT(shared_landmarks, every_time / 2) << shared_landmarks << " vs " << every_time;
  EXPECT_GT(r.stats[1].landmarks_fused, 0);
  EXPECT_LT(r.final_vehicle_error[1], 0.7 * baseline().final_vehicle_error[1]);
}

TEST(DcCooperation, OptionsLoadAndValidate) {
  auto node = ConfigNode::fromString(
      "ci_method: optimal_trace\nboth_ways: false\ncoop_sigma: 3\nmap_shared_landmarks: false\n",
      "coop.yaml");
  ASSERT_TRUE(node.ok());
  coop::DcCooperationOptions o;
  EXPECT_TRUE(o.map_shared_landmarks);
  ASSERT_TRUE(o.load(*node).ok());
  EXPECT_FALSE(o.map_shared_landmarks);
  EXPECT_EQ(o.ci_method, coop::CiMethod::kOptimalTrace);
  EXPECT_FALSE(o.both_ways);
  EXPECT_EQ(o.coop_sigma, 3.0);
  auto backoff = ConfigNode::fromString("merge: {max_place_backoff_s: 0.5}\n", "coop.yaml");
  EXPECT_FALSE(coop::DcCooperationOptions{}.load(*backoff).ok());
  auto reask = ConfigNode::fromString("reask_period_s: -1\n", "coop.yaml");
  EXPECT_FALSE(coop::DcCooperationOptions{}.load(*reask).ok());
  auto bad = ConfigNode::fromString("ci_method: best\n", "coop.yaml");
  ASSERT_TRUE(bad.ok());
  EXPECT_FALSE(coop::DcCooperationOptions{}.load(*bad).ok());
  auto neg = ConfigNode::fromString("coop_sigma: -1\n", "coop.yaml");
  EXPECT_FALSE(coop::DcCooperationOptions{}.load(*neg).ok());
  auto inverted =
      ConfigNode::fromString("min_request_timeout_s: 3\nrequest_timeout_s: 2\n", "coop.yaml");
  const Status s = coop::DcCooperationOptions{}.load(*inverted);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("min_request_timeout_s"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
