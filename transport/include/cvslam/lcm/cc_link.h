#pragma once
// Centralised cooperation of an agent process over LCM (cvslam_agent --mode cc,
// docs/ground_station.md; thesis §6.3): the CooperationLink that sends the ground station an
// observation batch per frame (coop/cc_batch_builder.h — the code cvslam_run --mode cc runs)
// on UAV<id>/OBS, publishes the agent's initial estimate on UAV<id>/POSE when its filter starts
// (the ground station starts the vehicle from it), and adopts the ground station's estimate:
// after sending a frame's batch it waits up to gs_wait_s for UAV<id>/GS_STATE of that frame —
// only while the ground station is alive (its heartbeat on UAV0/STATUS or a GS_STATE within
// gs_timeout_s) — and the POSE and the record of the frame are that estimate when it came in
// time, else the agent's own filter's, which always runs (the fallback). So a killed ground
// station costs no frame; a restarted one starts the vehicle from the agent's next POSE and
// takes over again. STATUS says `gs: fresh|stale|absent` with the frames adopted and own;
// agent_<id>/coop.csv logs every change (docs/run_format.md).

#include <condition_variable>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>

#include "cvslam/coop/cc_batch_builder.h"
#include "cvslam/lcm/agent_node.h"
#include "cvslam/slam/vehicle_estimate.h"

namespace cvslam::transport {

class CcLink final : public CooperationLink {
 public:
  /// `out_dir` (may be empty): the adoption log goes to out_dir/agent_<id>/coop.csv.
  CcLink(int self_id, const AgentNodeOptions::Cc& options, std::string out_dir);

  Status subscribe(LcmBus& bus) override;
  void drainInbound() override {}
  void onImu(const ImuSample& sample) override { builder_.addImu(sample); }
  Status onStart(AgentPipeline& agent, LcmBus& bus, const std::string& filter_name) override;
  Status afterFrame(AgentPipeline& agent, LcmBus& bus,
                    const std::function<void(cvslam::agent_summary_t&)>& fill_counters) override;
  const VehicleEstimate* adopted() const override { return adopted_ ? &*adopted_ : nullptr; }
  std::string statusText() const override;
  bool degraded() const override;
  bool sendsSummary() const override { return false; }
  std::string report() const override;

 private:
  enum class Gs { kFresh, kStale, kAbsent };
  static const char* name(Gs gs);
  double now() const;
  Status log(int64_t t_us);
  std::string refused() const;  // refused_, under the lock

  int id_;
  AgentNodeOptions::Cc o_;
  std::string out_dir_;
  coop::CcBatchBuilder builder_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::optional<VehicleEstimate> latest_;  // latest GS_STATE (mutex_)
  double gs_heard_s_;                      // wall time the ground station was last heard (mutex_)
  std::string refused_;  // the ground station's refusals of this UAV's batches (mutex_)
  std::optional<VehicleEstimate> adopted_;  // the last frame's, when adopted
  Gs gs_ = Gs::kAbsent;
  bool logged_ = false;
  std::ofstream log_;
  int64_t frames_adopted_ = 0, frames_own_ = 0, takeovers_ = 0;
};

}  // namespace cvslam::transport
