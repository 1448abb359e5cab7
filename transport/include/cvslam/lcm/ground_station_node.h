#pragma once
// The LCM side of the ground station (cvslam_ground_station, docs/ground_station.md; CC-VSLAM,
// thesis §6.3): subscribes every UAV's UAV<id>/OBS (observation batches), UAV<id>/POSE (the
// agent's own estimate: starts a vehicle, and restarts it after the agent or the ground station
// restarted), UAV<id>/STATUS (progress, liveness) and UAV<id>/GT (truth for the record, when a
// replay publishes it); orders the work across agents (coop/cc_event_orderer.h), runs the joint
// filter (coop/cc_team_filter.h), and publishes UAV<id>/GS_STATE right after each batch of that
// UAV, GS/MAP every map_period_s of dataset time and its heartbeat + progress on UAV0/STATUS
// (a lockstep replay includes it with --participants …,0). A UAV silent for agent_timeout_s is
// marginalised out, the others go on; it is started again from its next POSE. Writes
// DIR/ground_station/ (coop/ground_station_recorder.h).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "cvslam/coop/cc_event_orderer.h"
#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/coop/ground_station_recorder.h"
#include "cvslam/core/status.h"
#include "cvslam/io/run_record.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::transport {

struct GroundStationNodeOptions {
  std::vector<int> agents;  ///< UAV ids served (--agents)
  std::string url = kDefaultLcmUrl;
  std::shared_ptr<const TeamKey> auth_key;  ///< set: cooperation messages signed (message_auth.h)
  std::string out_dir;                      ///< run folder; empty: no record
  std::string filter_name = "ekf";          ///< gs_state_t.filter
  double status_period_s = 0.2;             ///< heartbeat on UAV0/STATUS (wall) [s]
  double map_period_s = 1.0;                ///< GS/MAP period (dataset time) [s]
  double agent_timeout_s = 1.0;             ///< a UAV silent this long is dropped (wall) [s]
  double flush_period_s = 5.0;              ///< run record written every … (wall) [s]
  double startup_wait_s = 2.0;        ///< announce on STATUS once every UAV was heard, or after
  double idle_exit_s = 0.0;           ///< exit after this long without agent messages (0: never)
  std::size_t inbox_capacity = 4096;  ///< messages waiting for the main thread; full → dropped
  bool verbose = false;

  /// Section `ground_station:` of config/ground_station.yaml (periods, timeouts).
  Status load(const ConfigNode& node);
};

/// What the ground station knows of one UAV in advance: its camera, its IMU noise and, in
/// simulation, the true landmarks (for the record's map).
struct GroundStationAgent {
  StereoCamera camera;
  InsPropagatorOptions ins;
  coop::GroundStationRecorder::LandmarkTruth landmark_truth;
};

class GroundStationNode {
 public:
  static Expected<std::unique_ptr<GroundStationNode>> create(
      const GroundStationNodeOptions& options, const coop::CcTeamFilterOptions& filter,
      std::map<int, GroundStationAgent> agents, const RunInfo& info);
  ~GroundStationNode();

  /// Runs until *stop or idle exit; processes what is queued, writes the record.
  Status run(const std::atomic<bool>& stop);
  /// One line per run for stdout: batches, rejections, step time, traffic.
  std::string report() const;

 private:
  struct Inbound {
    enum class Kind { kBatch, kPose, kStatus, kTruth };
    Kind kind = Kind::kBatch;
    int agent_id = 0;
    int64_t seq = 0;
    int64_t t_us = 0;
    coop::CcObservationBatch batch;
    VehicleEstimate estimate;           ///< kPose
    Vector9d truth = Vector9d::Zero();  ///< kTruth
    double arrival_s = 0.0;
  };

  GroundStationNode(const GroundStationNodeOptions& options,
                    const coop::CcTeamFilterOptions& filter,
                    std::map<int, GroundStationAgent> agents);
  Status subscribe();
  void push(Inbound in);
  /// A message dropped before the filter: its sender (0 unknown) and size (−1 unknown) go to
  /// the record's per-UAV counts and dropped_bytes_per_reason.
  void countDropped(const std::string& reason, int agent_id = 0, int64_t bytes = -1);
  void take(Inbound& in);
  Status work(bool flush);
  Status step(coop::CcEvent& event);
  Status startVehicle(const coop::CcEvent& event);
  Status publishStatus(bool final);
  Status publishMap(int64_t t_us);
  Status flushRecord(bool final);
  const Vector9d* truthAt(int agent_id, int64_t t_us) const;
  double now() const;

  GroundStationNodeOptions o_;
  std::map<int, GroundStationAgent> agents_;
  coop::CcTeamFilter filter_;
  coop::CcEventOrderer orderer_;
  coop::GroundStationRecorder recorder_;
  bool recording_ = false;
  std::unique_ptr<LcmBus> bus_;

  mutable std::mutex inbox_mutex_;
  std::condition_variable inbox_cv_;
  std::vector<Inbound> inbox_;
  std::map<std::string, int64_t> dropped_;  // before the filter, per reason (inbox_mutex_)
  struct Drop {
    std::string reason;
    int agent_id;
    int64_t bytes;
  };
  std::vector<Drop> drops_unrecorded_;             // not yet given to the recorder (inbox_mutex_)
  std::map<std::string, int64_t> bytes_received_;  // per stream (inbox_mutex_)
  double last_agent_message_s_ = 0.0;              // inbox_mutex_

  std::map<int, int64_t> last_seq_obs_, last_seq_pose_;  // restart detection
  std::map<int, std::deque<std::pair<int64_t, Vector9d>>> truth_;
  std::map<int, int64_t> pending_start_;  // agent → time of its queued start
  bool announced_ = false;
  double start_s_ = 0.0;
  int64_t last_map_us_ = -1;
  int64_t restarts_ = 0, timeouts_ = 0, resets_ = 0, starts_ = 0, published_states_ = 0;
  std::set<std::pair<int, std::string>> refusals_told_;  // (UAV, reason) said once on stderr
};

}  // namespace cvslam::transport
