#pragma once
// Decentralised cooperation of an agent process over LCM (docs/architecture.md, docs/conventions.md; thesis §6.6.5):
// the CooperationLink of cvslam_agent --mode dc. Subscribes TEAM/SUMMARY, every agent's
// INDEX (the pattern UAV[0-9]+/INDEX: peers may appear with any id), and its own
// UAV<id>/SHARED_REQ and UAV<id>/SHARED; converts with coop_convert.h (the same converters and
// validation as cvslam_run --mode dc) and runs one coop::DcCooperation.
//
// Determinism: inbound messages are handed to DcCooperation right before the frame that may
// apply them (those older than the frame), in the order cvslam_run delivers them — by time,
// sender id, stream (summary, index, request, shared), sequence number — whatever order they
// arrived in. A lockstep run then reproduces cvslam_run --mode dc.

#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <variant>
#include <vector>

#include "cvslam/coop/dc_cooperation.h"
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

  const coop::DcCooperation& cooperation() const { return dc_; }

 private:
  using Message = std::variant<coop::CoopSummary, coop::FeatureIndexList, coop::SharedRequest,
                               coop::SharedLandmarks>;
  /// (t_us, sender, stream rank = variant index, seq, arrival order)
  using Key = std::tuple<int64_t, int, std::size_t, int64_t, uint64_t>;

  void receive(Message m);
  Status writeEvents();

  int self_;
  coop::DcCooperation dc_;
  std::string out_dir_;
  std::ofstream csv_;
  std::mutex mutex_;
  std::vector<Message> arrived_;    // receive thread → main thread
  std::map<Key, Message> pending_;  // main thread, canonical order
  uint64_t arrivals_ = 0;
  int64_t refused_ = 0;  // DcCooperation rejected on arrival
};

}  // namespace cvslam::transport
