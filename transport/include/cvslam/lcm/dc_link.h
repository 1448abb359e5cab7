#pragma once
// Decentralised cooperation of an agent process over LCM (docs/architecture.md,
// docs/conventions.md; thesis §6.6.5): the CooperationLink of cvslam_agent --mode dc, the thin LCM
// adapter of the DC link (coop/dc_link_core.h). Subscribes TEAM/SUMMARY, every agent's INDEX (the
// pattern UAV[0-9]+/INDEX: peers may appear with any id), and its own UAV<id>/SHARED_REQ and
// UAV<id>/SHARED; converts with coop_convert.h (the same converters and validation as
// cvslam_run --mode dc) and hands the messages to its DcLinkCore, which orders them, runs the
// cooperation and writes coop.csv exactly as cvslam_run does: a lockstep run reproduces
// cvslam_run --mode dc. Publishes the core's outbox.

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "cvslam/coop/dc_link_core.h"
#include "cvslam/coop/peer_link_monitor.h"
#include "cvslam/lcm/agent_node.h"

namespace cvslam::transport {

class DcLink final : public CooperationLink {
 public:
  /// `out_dir` (may be empty): cooperation events go to out_dir/agent_<id>/coop.csv.
  DcLink(int self_id, const coop::DcCooperationOptions& options, int64_t boot_id,
         std::string out_dir);

  Status subscribe(LcmBus& bus) override;
  void drainInbound() override;
  Status afterFrame(AgentPipeline& agent, LcmBus& bus,
                    const std::function<void(cvslam::agent_summary_t&)>& fill_counters) override;
  std::string report() const override;
  bool teamState(const Vector9d& x_own, int* root, Vector9d* x_team) const override {
    return core_.cooperation().teamState(x_own, root, x_team);
  }
  /// For STATUS: the peers known now, the peer events so far and each peer's link ("peers 2,3;
  /// timeouts 0; restarts 0; links 2: 118/120 age 0.10 s, 3: …", received of expected by seq,
  /// age of its newest news in data time), so tests and tools can wait on events instead of
  /// sleeping and a lossy link shows.
  std::string statusText() const override;

  const coop::DcCooperation& cooperation() const { return core_.cooperation(); }

 private:
  void receive(coop::CoopMessage m);

  coop::DcLinkCore core_;
  std::string out_dir_;
  bool log_open_ = false;
  mutable std::mutex mutex_;
  coop::PeerLinkMonitor links_;             // under mutex_
  std::vector<coop::CoopMessage> arrived_;  // receive thread → main thread
  int64_t first_frame_us_ = -1, last_frame_us_ = -1;
};

}  // namespace cvslam::transport
