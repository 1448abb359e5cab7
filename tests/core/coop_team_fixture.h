#pragma once
// A two-UAV feature-level team with one DcCooperation per agent, for the cooperation tests.
// Messages go straight from one agent's outbox to the other's on*() (DcCooperation queues them
// and applies them at the receiver's next frame, the epoch semantics); a test can drop,
// duplicate, hold back, reorder or corrupt them through `transport`.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"

namespace cvslam::cooptest {

/// UAV1: accurate start. UAV2: 10° behind on the same 25 m circle (≈ 1.5 s later over the same
/// ground), its initial position 1σ = 1.5 m, sampled (perturb) — its map starts offset.
/// `offset_start` false: UAV2 starts at a known pose too (thesis §6.3.1), like UAV1.
/// offset_start: UAV2 starts 1.5 m off (1σ); exact_starts: both estimates start at the truth
/// (perturb: false; otherwise they are sampled from the default 0.1 m / 1° uncertainty).
inline std::string twoUavScenario(double duration, uint64_t seed, bool offset_start = true,
                                  bool exact_starts = false) {
  const std::string common =
      "    camera_rate_hz: 10.0\n"
      "    pixel_noise: {kind: gaussian, sigma_px: 0.5}\n";
  const std::string exact = exact_starts ? "    initial_uncertainty: {perturb: false}\n" : "";
  return "name: coop_pair\nseed: " + std::to_string(seed) +
         "\nduration: " + std::to_string(duration) +
         "\nworld: {relief_amplitude: 1.0, landmark_density: 0.5, margin: 30.0}\n"
         "agents:\n"
         "  - id: 1\n"
         "    trajectory: {kind: circle, centre: [0.0, 0.0], radius: 25.0, altitude: 10.0, "
         "speed: 3.0, heading: velocity, tilt: bank}\n" +
         common + exact +
         "  - id: 2\n"
         "    trajectory: {kind: circle, centre: [0.0, 0.0], radius: 25.0, altitude: 10.0, "
         "speed: 3.0, heading: velocity, tilt: bank, start_angle_deg: -10.0}\n" +
         std::string(
             offset_start
                 ? "    initial_uncertainty: {position_sigma: [1.5, 1.5, 0.5], perturb: true}\n"
                 : exact) +
         common;
}

/// One message in flight: exactly one of the four is set.
struct Envelope {
  int from = 0;
  std::optional<coop::CoopSummary> summary;
  std::optional<coop::FeatureIndexList> index;
  std::optional<coop::SharedRequest> request;
  std::optional<coop::SharedLandmarks> shared;
};

struct TeamResult {
  coop::DcCooperationStatistics stats[2];
  std::vector<coop::CoopEvent> events[2];
  double final_vehicle_error[2] = {0, 0};
  double final_landmark_error[2] = {0, 0};  ///< mean |p − p_true| of in-state landmarks
  /// Fused pairs: (own landmark id, the sender's id of its landmark, -1 if unknown).
  std::vector<std::pair<int64_t, int64_t>> fused_pairs[2];
  bool ok = false;
};

/// transport(t_us of the sending frame, message) returns the messages to deliver now (the
/// default delivers it unchanged). restart_at_us: agent 2's DcCooperation is replaced by a
/// fresh instance (new boot_id) at that time. deaf_after_us: nothing is delivered after it.
struct TeamOptions {
  coop::DcCooperationOptions coop;
  bool cooperate = true;
  std::function<std::vector<Envelope>(int64_t, Envelope)> transport;
  int64_t restart_at_us = -1;
  int64_t deaf_after_us = -1;
};

inline void deliver(coop::DcCooperation& to, const Envelope& e) {
  if (e.summary) to.onSummary(*e.summary);
  if (e.index) to.onIndex(*e.index);
  if (e.request) to.onRequest(*e.request);
  if (e.shared) to.onShared(*e.shared);
}

/// The pair's filters, not yet flown; nullptr, with a test failure, if they cannot be built.
inline std::unique_ptr<SimulatedTeamRun> createPair(double duration, uint64_t seed,
                                                    const VisualInertialSlamOptions& options = {}) {
  auto sc = sim::Scenario::fromString(twoUavScenario(duration, seed), "coop_pair.yaml");
  EXPECT_TRUE(sc.ok()) << sc.status().message();
  if (!sc.ok()) return nullptr;
  auto run = SimulatedTeamRun::create(*sc, options);
  EXPECT_TRUE(run.ok()) << run.status().message();
  return run.ok() ? std::move(*run) : nullptr;
}

/// The pair's own filters flown for `duration` s without cooperation (for tests of one fusion
/// on UAV2's filter, whose start is offset); nullptr, with a test failure, if it cannot run.
inline std::unique_ptr<SimulatedTeamRun> flyPairAlone(
    double duration, uint64_t seed, const VisualInertialSlamOptions& options = {}) {
  std::unique_ptr<SimulatedTeamRun> run = createPair(duration, seed, options);
  if (run == nullptr) return nullptr;
  const Status s = run->run({});
  EXPECT_TRUE(s.ok()) << s.message();
  return s.ok() ? std::move(run) : nullptr;
}

inline TeamResult runTeam(double duration, uint64_t seed, const TeamOptions& opt) {
  TeamResult out;
  const std::unique_ptr<SimulatedTeamRun> run = createPair(duration, seed);
  if (run == nullptr) return out;
  coop::DcCooperationOptions co = opt.coop;
  co.true_ids = true;
  std::unique_ptr<coop::DcCooperation> agents[2] = {
      std::make_unique<coop::DcCooperation>(1, co, 1001),
      std::make_unique<coop::DcCooperation>(2, co, 2001)};
  bool restarted = false;
  Status s = run->run([&](const SimulatedFrame& f) {
    const int self = f.agent_id - 1, peer = 1 - self;
    if (!opt.cooperate) return Status::Ok();
    if (self == 1 && opt.restart_at_us >= 0 && f.t_us >= opt.restart_at_us && !restarted) {
      agents[1] = std::make_unique<coop::DcCooperation>(2, co, 2002);
      restarted = true;
    }
    StereoFrameObservations frame;
    frame.t_us = f.t_us;
    coop::CoopOutbox box;
    if (Status st = agents[self]->afterFrame(frame, *f.mutable_slam, &box); !st.ok()) return st;
    std::vector<Envelope> sent;
    auto push = [&](Envelope e) {
      e.from = f.agent_id;
      sent.push_back(std::move(e));
    };
    if (box.summary) push({0, box.summary, {}, {}, {}});
    if (box.index) push({0, {}, box.index, {}, {}});
    for (const auto& r : box.requests) push({0, {}, {}, r, {}});
    for (const auto& l : box.shared) push({0, {}, {}, {}, l});
    if (opt.deaf_after_us >= 0 && f.t_us > opt.deaf_after_us) return Status::Ok();
    for (Envelope& e : sent) {
      if (opt.transport) {
        // A transport may release messages of either sender: each goes to the other agent.
        for (const Envelope& d : opt.transport(f.t_us, std::move(e)))
          deliver(*agents[d.from == 1 ? 1 : 0], d);
      } else {
        deliver(*agents[peer], e);
      }
    }
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  for (int i = 0; i < 2; ++i) {
    out.stats[i] = agents[i]->statistics();
    out.events[i] = agents[i]->takeEvents();
    for (const coop::FusedMatch& m : agents[i]->fusedMatches())
      out.fused_pairs[i].emplace_back(m.local_id,
                                      agents[1 - i]->sentLandmarkId(m.peer_seq, m.slot));
    const VisualInertialSlam& slam = run->slam(static_cast<std::size_t>(i));
    const sim::GroundTruth truth =
        run->simulator().agent(static_cast<std::size_t>(i)).truth(slam.time());
    out.final_vehicle_error[i] = (slam.vehicleState().head<3>() - truth.p_BinN).norm();
    double sum = 0.0;
    int n = 0;
    for (const StateLandmark& l : slam.stateLandmarks()) {
      Eigen::Vector3d p;
      if (!run->sensing(static_cast<std::size_t>(i)).landmarkTruth(l.id, &p)) continue;
      sum += (l.p_LinN - p).norm();
      ++n;
    }
    out.final_landmark_error[i] = n > 0 ? sum / n : NAN;
  }
  out.ok = s.ok();
  return out;
}

}  // namespace cvslam::cooptest
