#pragma once
// The LCM side of one agent process (cvslam_agent, docs/architecture.md, docs/run_format.md):
// subscribes the agent's sensor streams, puts them back in dataset-time order
// (sensor_event_orderer.h) and feeds its AgentPipeline; publishes UAV<id>/POSE (agent_state_t)
// after every frame, TEAM/SUMMARY as heartbeat with the per-channel receive counters, and
// UAV<id>/STATUS (processed-up-to time, for lockstep, docs/replay.md) after every batch and
// periodically. In DC mode a CooperationLink runs the exchange with the peers; it publishes its
// outbox before the STATUS, so a lockstep run delivers it to every peer before the next epoch.
// Writes the run record (agent_run_recorder.h) periodically and at the end.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/message_types.h"
#include "cvslam/merge/frame_relation.h"
#include "cvslam/sensors/sensor_event_orderer.h"
#include "cvslam/slam/agent_calibration.h"
#include "cvslam/slam/agent_pipeline.h"
#include "cvslam/slam/agent_run_recorder.h"
#include "cvslam/slam/unknown_pose_start.h"
#include "cvslam/slam/vehicle_estimate.h"

namespace cvslam::transport {

struct AgentNodeOptions {
  int id = 1;                   ///< this UAV's id (≥ 1)
  std::string mode = "single";  ///< single | dc | cc (summary's mode field)
  std::string url = kDefaultLcmUrl;
  std::shared_ptr<const TeamKey> auth_key;  ///< set: cooperation messages signed (message_auth.h)
  /// Set: cooperation (TEAM/SUMMARY, INDEX, SHARED_REQ, SHARED, OBS, GS_STATE, GS/MAP) on this
  /// provider, e.g. a LAN (ttl=1), while the sensor streams stay on `url` (the vehicle's own
  /// loopback; scripts/netns_team.sh). Empty: everything on `url`.
  std::string coop_url;
  std::string out_dir;              ///< run record folder; empty: none
  std::string filter_name = "ekf";  ///< agent_state_t.filter
  double status_period_s = 0.2;     ///< STATUS heartbeat period (wall) [s]
  double summary_period_s = 1.0;    ///< single mode: SUMMARY period (dataset time) [s]
  /// The receive counters per channel ride on a SUMMARY at most every … (dataset time) [s];
  /// 0: on every one. They are for watching the links (lcm-spy) and most of a summary's bytes.
  double counters_period_s = 5.0;
  double flush_period_s = 5.0;    ///< run record written every … (wall) [s]
  double map_period_s = 1.0;      ///< UAV<id>/MAP (for displays) every … (dataset) [s]; 0: never
  double idle_exit_s = 0.0;       ///< exit after this long without sensor data (0: never) [s]
  double max_wait_s = 0.3;        ///< orderer: release a frame without IMU past it after [s]
  std::size_t imu_queue = 20000;  ///< inbound buffers (messages); full → dropped, counted
  std::size_t frame_queue = 64;
  int64_t boot_id = 0;  ///< random per process start (summary)
  /// Initial 1σ when the filter starts at the first ground truth (EuRoC calibration), and of
  /// the frame's position and yaw when it starts at rest.
  InitialUncertainty initial_sigma;
  /// How the filter starts. known: at the scenario's initial estimate, else at the first
  /// ground truth (thesis §6.3.1, a team in one frame). rest | dynamic | auto: without ground
  /// truth, in the agent's own gravity-aligned frame (slam/unknown_pose_start.h: static_init,
  /// dynamic_init, give_up_s; evaluate with `cvslam_eval --align yaw`).
  enum class Start { kKnown, kRest, kDynamic, kAuto };
  Start start = Start::kKnown;
  UnknownPoseStartOptions unknown_pose;
  /// Centralised mode (cc_link.h), `agent.cc:`.
  struct Cc {
    /// After sending a frame's batch, wait this long for the ground station's estimate of the
    /// frame (wall) [s]; lockstep runs are deterministic only when it always comes in time.
    double gs_wait_s = 0.25;
    /// The ground station is alive while heard within this (wall) [s]; else no waiting.
    double gs_timeout_s = 1.0;
    Status load(const ConfigNode& node);
  };
  Cc cc;
  bool verbose = false;

  /// agent.yaml section `agent:` (status_period_s, summary_period_s, counters_period_s,
  /// flush_period_s, map_period_s,
  /// max_wait_s, imu_queue, frame_queue, initial: {position_sigma, velocity_sigma,
  /// attitude_sigma_deg}, start: known | rest | dynamic | auto, static_init: {window_s,
  /// segments, max_accel_mean_change, max_gyro_mean_change, max_gravity_error},
  /// dynamic_init: {...}, start_give_up_s, cc: {gs_wait_s, gs_timeout_s}); id, mode, url,
  /// out_dir, idle_exit_s come from the command line.
  Status load(const ConfigNode& node);
};

/// Cooperation of the agent with its peers (DC mode, dc_link.h) or with the ground station (CC
/// mode, cc_link.h), plugged into the node.
class CooperationLink {
 public:
  virtual ~CooperationLink() = default;
  /// Every IMU sample the agent's filter was given, in order.
  virtual void onImu(const ImuSample&) {}
  /// The agent's filter has just started (before its first IMU sample).
  virtual Status onStart(AgentPipeline&, LcmBus&, const std::string& /*filter_name*/) {
    return Status::Ok();
  }
  /// After afterFrame(): the estimate published and recorded for the frame in place of the
  /// agent's own (cc: the ground station's, when it came in time); null: the agent's own.
  virtual const VehicleEstimate* adopted() const { return nullptr; }
  /// For STATUS' message; empty: nothing to say.
  virtual std::string statusText() const { return {}; }
  /// The link's peer reports a problem with this agent's messages (STATUS health DEGRADED).
  virtual bool degraded() const { return false; }
  /// After afterFrame(): the own state `x_own` in the team's frame and that frame's root, when
  /// the link estimated the frames between the agents and this agent merged
  /// (trajectory_team.tum); false otherwise.
  virtual bool teamState(const Vector9d& /*x_own*/, int* /*root*/, Vector9d* /*x_team*/) const {
    return false;
  }
  /// True when the link publishes TEAM/SUMMARY itself; else the node does, periodically.
  virtual bool sendsSummary() const { return true; }
  /// Subscribes the cooperation channels (before the bus starts).
  virtual Status subscribe(LcmBus& bus) = 0;
  /// Hands the messages received so far to the cooperation core (main thread; called after
  /// the sensor inbox was drained, so everything that arrived before those sensor messages
  /// is included).
  virtual void drainInbound() = 0;
  /// Right after a frame: runs the cooperation and publishes its outbox. `fill_counters`
  /// adds the node's per-channel counters to an outgoing summary.
  virtual Status afterFrame(AgentPipeline& agent, LcmBus& bus,
                            const std::function<void(cvslam::agent_summary_t&)>& fill_counters) = 0;
  /// One line for the final report.
  virtual std::string report() const = 0;
};

using LandmarkTruthFn = AgentRunRecorder::LandmarkTruth;

class AgentNode {
 public:
  static Expected<std::unique_ptr<AgentNode>> create(const AgentNodeOptions& options,
                                                     AgentCalibration calibration,
                                                     std::optional<VisualSlamPipeline> images,
                                                     std::unique_ptr<CooperationLink> coop);
  ~AgentNode();

  /// Runs until *stop becomes true or --idle-exit; processes what is left, writes outputs.
  Status run(const std::atomic<bool>& stop);

  /// Summary of the run for stdout.
  std::string report() const;

 private:
  struct Inbound {
    SensorEvent event;
    double arrival_s;
    /// A stereo pair as it arrived: decoded by run()'s thread, so that the receive thread
    /// only copies bytes (a PNG pair takes milliseconds to decode).
    std::shared_ptr<const cvslam::stereo_image_t> image;
  };
  AgentNode(const AgentNodeOptions& options, AgentCalibration calibration);
  Status subscribe();
  void push(SensorEvent&& event, const std::string& channel, std::size_t capacity,
            std::shared_ptr<const cvslam::stereo_image_t> image = nullptr);
  /// Decodes the batch's stereo pairs and hands the batch to the orderer (run()'s thread).
  void order(std::vector<Inbound>& batch);
  Status processEvent(SensorEvent& event, double arrival_s);
  void handle(SensorEvent& event, double arrival_s);
  Status startPipeline(const AgentFilterSetup& setup);
  /// start: rest | dynamic | auto — an event before the start, then the start once found.
  Status startUnknownPose(const SensorEvent& event);
  /// Gives the sample to the filter and to the cooperation link.
  Status addImu(const ImuSample& sample);
  Status afterFrame(double arrival_s);
  Status publishStatus();
  /// Wall time of the latest sensor message, or of the start [s].
  double lastArrival() const;
  Status publishSummary();
  void fillCounters(cvslam::agent_summary_t& msg);
  Status flushRecord(bool final);
  double now() const;

  AgentNodeOptions o_;
  AgentCalibration calibration_;
  /// calibration_.own_frame_in_world as the relation world → own (UAV<N>/GT recorded there).
  std::optional<merge::FrameRelation> world_in_own_;
  std::optional<VisualSlamPipeline> images_;
  std::unique_ptr<CooperationLink> coop_;
  std::unique_ptr<LcmBus> bus_;
  std::unique_ptr<LcmBus> coop_bus_;  ///< only with AgentNodeOptions::coop_url
  LcmBus& coopBus() { return coop_bus_ ? *coop_bus_ : *bus_; }
  /// Counters of both buses.
  std::vector<ChannelCounters> allCounters() const;
  std::unique_ptr<AgentPipeline> agent_;
  AgentRunRecorder recorder_;
  SensorEventOrderer orderer_;

  mutable std::mutex inbox_mutex_;
  std::condition_variable inbox_cv_;
  std::vector<Inbound> inbox_;
  std::map<std::string, std::size_t> inbox_count_;  // per channel, in inbox_
  std::map<std::string, int64_t> dropped_;          // queue full, per channel
  std::map<std::string, int64_t> rejected_;         // wrong sender or undecodable pair
  int64_t late_ = 0;                                // out of order (orderer)
  int64_t before_start_ = 0;                        // IMU / frames before the first pose
  std::optional<ImuSample> pre_start_imu_;
  std::unique_ptr<UnknownPoseStart> unknown_start_;  // start: rest | dynamic | auto
  Status fatal_;  // the node cannot go on (no start without ground truth)
  bool start_decided_ = false;
  std::optional<std::pair<int64_t, Vector9d>> truth_;  // latest ground truth
  int64_t processed_us_ = -1;
  // The latest handled event was an IMU or GT sample: a frame of the same time may still be
  // on its way (cvslam_replay publishes an instant's frame last), see publishStatus().
  bool frame_may_follow_ = false;
  int64_t last_summary_us_ = -1;
  int64_t last_counters_us_ = -1;  ///< when a SUMMARY last carried the counters
  int64_t last_map_us_ = -1;
  double last_arrival_s_ = 0.0;  // wall time of the latest sensor message (inbox_mutex_)
  double start_s_ = 0.0;
  std::vector<double> latencies_ms_;
  int64_t feature_frames_ = 0, image_frames_ = 0;
  int64_t frames_skipped_ = 0;  // frames of a kind the agent cannot process
  int64_t errors_ = 0;          // processing errors (reported in STATUS)
  std::string last_error_;
};

}  // namespace cvslam::transport
