#include "cvslam/lcm/ground_station_node.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "cvslam/io/config_node.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/cc_convert.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/sensor_convert.h"

namespace cvslam::transport {
namespace {

using Clock = std::chrono::steady_clock;

/// Ground-truth samples kept per UAV to find a batch's truth (≥ 1 s at 200 Hz).
constexpr std::size_t kTruthKept = 400;

std::string reasonOf(coop::CcEventOrderer::Push p) {
  return p == coop::CcEventOrderer::Push::kUnknownAgent ? "unknown_agent" : "reordered";
}

}  // namespace

Status GroundStationNodeOptions::load(const ConfigNode& node) {
  node.get("status_period_s", status_period_s);
  node.get("map_period_s", map_period_s);
  node.get("agent_timeout_s", agent_timeout_s);
  node.get("flush_period_s", flush_period_s);
  node.get("startup_wait_s", startup_wait_s);
  node.check(status_period_s > 0.0, "status_period_s", "must be > 0");
  node.check(map_period_s > 0.0, "map_period_s", "must be > 0");
  node.check(agent_timeout_s > status_period_s, "agent_timeout_s",
             "must exceed status_period_s (the agents' heartbeat)");
  node.check(flush_period_s > 0.0, "flush_period_s", "must be > 0");
  node.check(startup_wait_s >= 0.0, "startup_wait_s", "must be ≥ 0");
  return node.status();
}

GroundStationNode::GroundStationNode(const GroundStationNodeOptions& options,
                                     const coop::CcTeamFilterOptions& filter,
                                     std::map<int, GroundStationAgent> agents)
    : o_(options),
      agents_(std::move(agents)),
      filter_(filter),
      orderer_(options.agents, options.agent_timeout_s, now()) {}

GroundStationNode::~GroundStationNode() {
  if (bus_) bus_->stop();
}

double GroundStationNode::now() const {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

Expected<std::unique_ptr<GroundStationNode>> GroundStationNode::create(
    const GroundStationNodeOptions& options, const coop::CcTeamFilterOptions& filter,
    std::map<int, GroundStationAgent> agents, const RunInfo& info) {
  if (options.agents.empty()) return Status::Error("no agents to serve");
  if (Status s = checkLcmUrl(options.url); !s.ok()) return s;
  for (int id : options.agents)
    if (agents.count(id) == 0) return Status::Error("no calibration for UAV " + std::to_string(id));
  std::unique_ptr<GroundStationNode> node(
      new GroundStationNode(options, filter, std::move(agents)));
  BusOptions bus_options;
  bus_options.url = options.url;
  bus_options.auth_key = options.auth_key;
  auto bus = LcmBus::create(bus_options);
  if (!bus.ok()) return bus.status();
  node->bus_ = std::move(*bus);
  if (!options.out_dir.empty()) {
    if (Status s = node->recorder_.open(options.out_dir, info); !s.ok()) return s;
    node->recording_ = true;
  }
  if (Status s = node->subscribe(); !s.ok()) return s;
  return node;
}

void GroundStationNode::push(Inbound in) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    if (inbox_.size() >= o_.inbox_capacity) {
      ++dropped_["inbox_full"];
      return;
    }
    in.arrival_s = now();
    last_agent_message_s_ = in.arrival_s;
    inbox_.push_back(std::move(in));
  }
  inbox_cv_.notify_one();
}

void GroundStationNode::countDropped(const std::string& reason, int agent_id, int64_t bytes) {
  std::lock_guard<std::mutex> lock(inbox_mutex_);
  ++dropped_[reason];
  if (recording_) drops_unrecorded_.push_back({reason, agent_id, bytes});
}

Status GroundStationNode::subscribe() {
  auto count = [this](Stream stream, int64_t bytes) {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    bytes_received_[streamName(stream)] += bytes;
  };
  Status s = bus_->subscribe<cvslam::observation_batch_t>(
      allAgentsPattern(Stream::kObs), [this, count](const cvslam::observation_batch_t& m) {
        count(Stream::kObs, m.getEncodedSize());
        auto batch = fromMessage(m);
        if (!batch.ok())
          return countDropped("invalid", m.header.agent_id,
                              static_cast<int64_t>(m.getEncodedSize()));
        Inbound in;
        in.kind = Inbound::Kind::kBatch;
        in.agent_id = m.header.agent_id;
        in.seq = m.header.seq;
        in.t_us = m.header.utime;
        in.batch = std::move(*batch);
        push(std::move(in));
      });
  if (!s.ok()) return s;
  s = bus_->subscribe<cvslam::agent_state_t>(allAgentsPattern(Stream::kPose),
                                             [this, count](const cvslam::agent_state_t& m) {
                                               count(Stream::kPose, m.getEncodedSize());
                                               Inbound in;
                                               in.kind = Inbound::Kind::kPose;
                                               in.agent_id = m.header.agent_id;
                                               in.seq = m.header.seq;
                                               in.t_us = m.header.utime;
                                               in.estimate = estimateOf(m);
                                               push(std::move(in));
                                             });
  if (!s.ok()) return s;
  s = bus_->subscribe<cvslam::status_t>(allAgentsPattern(Stream::kStatus),
                                        [this](const cvslam::status_t& m) {
                                          if (m.header.agent_id == kGroundStationId) return;
                                          Inbound in;
                                          in.kind = Inbound::Kind::kStatus;
                                          in.agent_id = m.header.agent_id;
                                          in.t_us = m.processed_utime;
                                          push(std::move(in));
                                        });
  if (!s.ok()) return s;
  if (!recording_) return Status::Ok();
  for (int id : o_.agents) {
    // From the replay (sender −1): the UAV is in the channel's name only.
    s = bus_->subscribe<cvslam::pose_t>(channels::groundTruth(id),
                                        [this, id](const cvslam::pose_t& m) {
                                          Inbound in;
                                          in.kind = Inbound::Kind::kTruth;
                                          in.agent_id = id;
                                          in.t_us = m.header.utime;
                                          in.truth = truthState(fromPoseMessage(m));
                                          push(std::move(in));
                                        });
    if (!s.ok()) return s;
  }
  return Status::Ok();
}

const Vector9d* GroundStationNode::truthAt(int agent_id, int64_t t_us) const {
  auto it = truth_.find(agent_id);
  if (it == truth_.end()) return nullptr;
  const Vector9d* best = nullptr;
  int64_t best_dt = kTruthToleranceUs + 1;
  for (const auto& [t, x] : it->second) {
    const int64_t dt = std::llabs(t - t_us);
    if (dt < best_dt) {
      best_dt = dt;
      best = &x;
    }
  }
  return best;
}

/// Handles one message on the main thread: liveness and progress, restarts, events queued.
void GroundStationNode::take(Inbound& in) {
  const int id = in.agent_id;
  if (in.kind == Inbound::Kind::kTruth) {
    auto& q = truth_[id];
    q.emplace_back(in.t_us, in.truth);
    if (q.size() > kTruthKept) q.pop_front();
    return;
  }
  if (!orderer_.expects(id)) {
    if (in.kind != Inbound::Kind::kStatus) countDropped("unknown_agent");
    return;
  }
  if (in.kind == Inbound::Kind::kStatus) return orderer_.progress(id, in.t_us, in.arrival_s);
  // header.seq starts at 0 with every process start: a smaller one is a restarted agent, whose
  // vehicle restarts from its next POSE (its batches no longer follow the old ones).
  std::map<int, int64_t>& last = in.kind == Inbound::Kind::kPose ? last_seq_pose_ : last_seq_obs_;
  auto previous = last.find(id);
  if (previous != last.end() && in.seq < previous->second) {
    ++restarts_;
    last_seq_pose_.erase(id);
    last_seq_obs_.erase(id);
    orderer_.restart(id);
    pending_start_.erase(id);
    if (filter_.hasVehicle(id)) (void)filter_.removeVehicle(id);
    if (o_.verbose) std::fprintf(stderr, "cvslam_ground_station: UAV%d restarted\n", id);
  }
  last[id] = in.seq;
  coop::CcEvent event;
  event.agent_id = id;
  event.t_us = in.t_us;
  if (in.kind == Inbound::Kind::kPose) {
    // A POSE at t may precede the agent's batch at t (its start estimate is repeated until
    // the ground station answers): it finishes only what precedes t.
    if (filter_.hasVehicle(id) || pending_start_.count(id) > 0)
      return orderer_.progress(id, in.t_us - 1, in.arrival_s);
    event.kind = coop::CcEvent::Kind::kStart;
    event.start = std::move(in.estimate);
    pending_start_[id] = in.t_us;
  } else {
    event.kind = coop::CcEvent::Kind::kBatch;
    event.batch = std::move(in.batch);
  }
  const auto pushed = orderer_.push(std::move(event), in.arrival_s);
  if (pushed != coop::CcEventOrderer::Push::kQueued) {
    countDropped(reasonOf(pushed));
    if (in.kind == Inbound::Kind::kPose) pending_start_.erase(id);
  }
}

Status GroundStationNode::startVehicle(const coop::CcEvent& e) {
  pending_start_.erase(e.agent_id);
  const GroundStationAgent& a = agents_.at(e.agent_id);
  Status s = filter_.addVehicle(e.agent_id, a.camera, e.t_us, e.start.x_v, e.start.P_v, &a.ins);
  if (!s.ok()) {
    countDropped("bad_start");
    std::fprintf(stderr, "cvslam_ground_station: UAV%d: %s\n", e.agent_id, s.message().c_str());
    return Status::Ok();  // the agent's next POSE tries again
  }
  ++starts_;
  if (o_.verbose)
    std::fprintf(stderr, "cvslam_ground_station: UAV%d started at t = %.6f s\n", e.agent_id,
                 static_cast<double>(e.t_us) * 1e-6);
  return Status::Ok();
}

Status GroundStationNode::step(coop::CcEvent& e) {
  if (e.kind == coop::CcEvent::Kind::kStart) return startVehicle(e);
  coop::CcStepReport report;
  // A rejected batch is counted by the filter (statistics()) and changes nothing.
  (void)filter_.processBatch(e.batch, &report);
  if (recording_)
    if (Status s = recorder_.addStep(filter_, report, truthAt(e.agent_id, e.t_us)); !s.ok())
      return s;
  if (!report.accepted) {
    // Each kind of refusal once per UAV, with its reason (the rest are counted in STATUS).
    const std::string key = coop::refusalKey(report.refusal, report.defect);
    if (refusals_told_.insert({e.agent_id, key}).second)
      std::fprintf(stderr, "cvslam_ground_station: UAV%d batch at t = %.3f s refused (%s): %s\n",
                   e.agent_id, static_cast<double>(e.t_us) * 1e-6, key.c_str(),
                   report.reason.c_str());
    // The vehicle's IMU cannot reach the frame (a gap longer than cc.max_imu_gap_s): it
    // restarts from the agent's next POSE, as after a timeout. Other refusals leave a vehicle
    // that takes the next batch.
    if (report.refusal == coop::CcRefusal::kPropagation && filter_.hasVehicle(e.agent_id)) {
      ++resets_;
      (void)filter_.removeVehicle(e.agent_id);
      if (o_.verbose)
        std::fprintf(stderr, "cvslam_ground_station: UAV%d restarts: %s\n", e.agent_id,
                     report.reason.c_str());
    }
    return Status::Ok();
  }
  // The agent waits for this (cc_link.h): published right after its own batch.
  auto estimate = filter_.estimate(e.agent_id);
  if (!estimate.ok()) return estimate.status();
  auto msg = toMessage(*estimate, o_.filter_name, filter_.mapVersion());
  if (!msg.ok()) return msg.status();
  msg->header.agent_id = kGroundStationId;
  if (Status s = bus_->publish(channels::gsState(e.agent_id), *msg); !s.ok()) return s;
  ++published_states_;
  if (last_map_us_ < 0 || e.t_us - last_map_us_ >= std::llround(o_.map_period_s * 1e6))
    return publishMap(e.t_us);
  return Status::Ok();
}

Status GroundStationNode::publishMap(int64_t t_us) {
  last_map_us_ = t_us;
  auto msg = toMessage(filter_.map(), t_us, filter_.mapVersion());
  if (!msg.ok()) return msg.status();
  return bus_->publish(channels::gsMap(), *msg);
}

Status GroundStationNode::work(bool flush) {
  coop::CcEvent event;
  const double t = now();
  while (orderer_.pop(t, flush, &event))
    if (Status s = step(event); !s.ok()) return s;
  // A UAV silent for agent_timeout_s: marginalised out, the others go on without waiting.
  for (int id : orderer_.expire(t)) {
    ++timeouts_;
    pending_start_.erase(id);
    if (filter_.hasVehicle(id)) (void)filter_.removeVehicle(id);
    if (o_.verbose) std::fprintf(stderr, "cvslam_ground_station: UAV%d timed out\n", id);
  }
  return Status::Ok();
}

Status GroundStationNode::publishStatus(bool final) {
  const double t = now();
  // Lockstep discovery: announce only once every UAV was heard (so that no batch is ordered
  // before a UAV the ground station did not know of yet), or after startup_wait_s.
  if (!announced_ && !final) {
    if (!orderer_.heardAll() && t - start_s_ < o_.startup_wait_s) return Status::Ok();
    announced_ = true;
  }
  cvslam::status_t m{};
  m.processed_utime = orderer_.processedUpTo(t);
  m.header.utime = std::max<int64_t>(m.processed_utime, 0);
  m.header.agent_id = kGroundStationId;
  std::string vehicles;
  for (int id : filter_.vehicles()) vehicles += (vehicles.empty() ? "" : ",") + std::to_string(id);
  const coop::CcTeamStatistics& st = filter_.statistics();
  // Refused batches make the ground station degraded, and the message names each UAV's
  // reasons (coop::refusedCount reads them back: the agents report them, the view shows them).
  m.health = st.rejected() > 0 ? cvslam::status_t::HEALTH_DEGRADED : cvslam::status_t::HEALTH_OK;
  m.message = "gs: vehicles " + (vehicles.empty() ? std::string("none") : vehicles) + "; batches " +
              std::to_string(st.batches) + ", refused " + std::to_string(st.rejected()) + ": " +
              st.refusalSummary();
  return bus_->publish(channels::status(kGroundStationId), m);
}

Status GroundStationNode::flushRecord(bool final) {
  if (!recording_) return Status::Ok();
  std::map<std::string, int64_t> bytes;
  std::vector<Drop> drops;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    bytes.swap(bytes_received_);
    drops.swap(drops_unrecorded_);
  }
  for (const auto& [stream, n] : bytes) recorder_.addBytesReceived(stream, n);
  for (const Drop& d : drops) recorder_.addDropped(d.reason, d.agent_id, d.bytes);
  if (!final) return recorder_.flush(filter_);
  coop::GroundStationRecorder::LandmarkTruth truth;
  if (filter_.options().association == coop::CcAssociation::kTrueIds) {
    // Feature level: joint ids are true ids, any UAV's world knows them.
    for (const auto& [id, a] : agents_)
      if (a.landmark_truth) truth = a.landmark_truth;
  }
  return recorder_.close(filter_, truth);
}

Status GroundStationNode::run(const std::atomic<bool>& stop) {
  if (Status s = bus_->start(); !s.ok()) return s;
  start_s_ = now();
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    last_agent_message_s_ = start_s_;
  }
  double last_status = -1e300, last_flush = start_s_;
  std::vector<Inbound> batch;
  while (!stop) {
    double last_message = 0.0;
    {
      std::unique_lock<std::mutex> lock(inbox_mutex_);
      inbox_cv_.wait_for(lock, std::chrono::milliseconds(10), [this] { return !inbox_.empty(); });
      batch.swap(inbox_);
      last_message = last_agent_message_s_;
    }
    for (Inbound& in : batch) take(in);
    const bool progressed = !batch.empty();
    batch.clear();
    if (Status s = work(false); !s.ok()) return s;
    const double t = now();
    if (progressed || t - last_status >= o_.status_period_s) {
      last_status = t;
      if (Status s = publishStatus(false); !s.ok()) return s;
    }
    if (t - last_flush >= o_.flush_period_s) {
      last_flush = t;
      if (Status s = flushRecord(false); !s.ok()) return s;
    }
    if (o_.idle_exit_s > 0.0 && orderer_.size() == 0 && t - last_message >= o_.idle_exit_s) {
      if (o_.verbose)
        std::fprintf(stderr, "cvslam_ground_station: no agent message for %.1f s, exiting\n",
                     o_.idle_exit_s);
      break;
    }
  }
  bus_->stop();
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    batch.swap(inbox_);
  }
  for (Inbound& in : batch) take(in);
  if (Status s = work(true); !s.ok()) return s;
  return flushRecord(true);
}

std::string GroundStationNode::report() const {
  const coop::CcTeamStatistics& st = filter_.statistics();
  const TimeSummary steps = summariseTimes(st.step_ms);
  std::string dropped;
  std::lock_guard<std::mutex> lock(inbox_mutex_);
  for (const auto& [reason, n] : dropped_)
    dropped += (dropped.empty() ? "" : ", ") + reason + " " + std::to_string(n);
  char buf[2048];
  std::snprintf(buf, sizeof(buf),
                "ground station: batches %ld, refused %ld (%s); dropped before the filter: %s; "
                "vehicle starts %lld, agent restarts "
                "%lld, timeouts %lld, vehicle resets %lld; GS_STATE sent %lld; step median %.2f "
                "ms, p95 %.2f ms, max "
                "%.2f ms; max state size %d",
                st.batches, st.rejected(), st.refusalSummary().c_str(),
                dropped.empty() ? "none" : dropped.c_str(), static_cast<long long>(starts_),
                static_cast<long long>(restarts_), static_cast<long long>(timeouts_),
                static_cast<long long>(resets_), static_cast<long long>(published_states_),
                steps.median_ms, steps.p95_ms, steps.max_ms, st.max_state_size);
  return buf;
}

}  // namespace cvslam::transport
