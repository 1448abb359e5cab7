#pragma once
// The ground station's order of work (docs/ground_station.md; thesis §6.3): the agents' batches
// and vehicle starts arrive over the network from several processes, in any interleaving; the
// joint filter must see them in one order that does not depend on arrival — time, then agent id,
// a vehicle start before a batch of the same time — so that a lockstep run reproduces
// cvslam_run --mode cc. An event at (t, i) is released once every other live agent has reached
// t: its progress (latest batch or start time, or the "processed up to" time of its STATUS) is
// ≥ t, so nothing older can still come from it. An agent is live while it was heard within
// `agent_timeout_s` (wall time) — every expected agent counts as heard at the orderer's creation,
// so the first events wait for the agents not heard yet — a silent one is no longer waited for
// (expire()), and is live again when heard again. Transport-free: the process feeds it what it
// decoded.
//
// Rejected on arrival (never released): events of agents not expected, and batches not after
// the agent's previous batch or a released time of it (stale or reordered).

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <vector>

#include "cvslam/coop/cc_observation_batch.h"
#include "cvslam/slam/vehicle_estimate.h"

namespace cvslam::coop {

/// One unit of ground-station work.
struct CcEvent {
  enum class Kind { kStart = 0, kBatch = 1 };  ///< a start sorts before a batch of equal time
  Kind kind = Kind::kBatch;
  int agent_id = 0;
  int64_t t_us = 0;
  CcObservationBatch batch;  ///< kBatch
  VehicleEstimate start;     ///< kStart: the agent's own estimate to (re)start its vehicle from
};

class CcEventOrderer {
 public:
  enum class Push { kQueued, kUnknownAgent, kStale };

  /// `now_s`: wall time of the creation.
  CcEventOrderer(const std::vector<int>& expected_agents, double agent_timeout_s, double now_s);

  bool expects(int agent_id) const { return expected_.count(agent_id) > 0; }
  /// Anything from the agent at wall time now_s (liveness only).
  void heard(int agent_id, double now_s);
  /// The agent has sent everything up to t_us (its STATUS' processed_utime).
  void progress(int agent_id, int64_t t_us, double now_s);
  /// Queues an event; its time is the agent's progress too.
  Push push(CcEvent event, double now_s);
  /// The agent's process restarted: its previous batch times no longer bound the new ones.
  void restart(int agent_id);

  /// The next event in (t, agent, kind) order that no live agent can still precede;
  /// `flush`: without waiting (end of the run). False when none.
  bool pop(double now_s, bool flush, CcEvent* out);
  /// Agents live until now that have been silent for agent_timeout_s (each reported once).
  std::vector<int> expire(double now_s);

  bool live(int agent_id, double now_s) const;
  /// Every expected agent has been heard at least once.
  bool heardAll() const;
  /// Everything up to this time has been released (−1: nothing yet): the minimum progress of
  /// the live agents with nothing older queued, for the ground station's STATUS.
  int64_t processedUpTo(double now_s) const;
  std::size_t size() const { return queue_.size(); }

 private:
  using Key = std::tuple<int64_t, int, int>;  // t, agent, kind
  struct Agent {
    double last_heard_s = -1.0;
    bool ever_heard = false;
    int64_t progress_us = -1;
    int64_t last_batch_us = -1;  ///< latest batch queued or released
    bool expired = false;
  };

  std::set<int> expected_;
  double timeout_s_;
  std::map<int, Agent> heard_;
  std::map<Key, CcEvent> queue_;
  int64_t released_us_ = -1;
};

}  // namespace cvslam::coop
