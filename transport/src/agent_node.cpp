#include "cvslam/lcm/agent_node.h"

#include <type_traits>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <type_traits>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/cc_convert.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/sensor_convert.h"

namespace cvslam::transport {
namespace {

using Clock = std::chrono::steady_clock;

/// Largest plausible agent id in a header (the replay is −1, the ground station 0).
constexpr int32_t kMaxAgentId = 1000000;
/// Data starting later than this after the scenario's initial estimate: the agent joins a
/// running team and starts at the first ground truth [µs].
constexpr int64_t kLateStartUs = 100000;
/// The cooperation streams: bytes_sent of stats.json and the bandwidth target.
/// In cc mode, the observation batches to the ground station.
const std::vector<Stream> kCoopStreams = {Stream::kTeamSummary, Stream::kIndex, Stream::kSharedReq,
                                          Stream::kShared, Stream::kObs};

}  // namespace

AgentNode::AgentNode(const AgentNodeOptions& options, AgentCalibration calibration)
    : o_(options),
      calibration_(std::move(calibration)),
      orderer_(SensorEventOrdererOptions{options.max_wait_s}) {
  if (calibration_.own_frame_in_world) {
    merge::FrameRelation own_in_world;
    own_in_world.x = *calibration_.own_frame_in_world;
    world_in_own_ = own_in_world.inverse();
  }
}

AgentNode::~AgentNode() {
  if (bus_) bus_->stop();
  if (coop_bus_) coop_bus_->stop();
}

double AgentNode::now() const {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

Expected<std::unique_ptr<AgentNode>> AgentNode::create(const AgentNodeOptions& options,
                                                       AgentCalibration calibration,
                                                       std::optional<VisualSlamPipeline> images,
                                                       std::unique_ptr<CooperationLink> coop) {
  if (options.id < 1) return Status::Error("agent id must be ≥ 1");
  if (Status s = checkLcmUrl(options.url); !s.ok()) return s;
  std::unique_ptr<AgentNode> node(new AgentNode(options, std::move(calibration)));
  node->images_ = std::move(images);
  node->coop_ = std::move(coop);
  BusOptions bus_options;
  bus_options.url = options.url;
  bus_options.auth_key = options.auth_key;
  bus_options.receive.accept_agent = [](int32_t id) { return id >= -1 && id <= kMaxAgentId; };
  auto bus = LcmBus::create(bus_options);
  if (!bus.ok()) return bus.status();
  node->bus_ = std::move(*bus);
  if (!options.coop_url.empty()) {
    if (Status s = checkLcmUrl(options.coop_url); !s.ok()) return s;
    bus_options.url = options.coop_url;
    auto coop_bus = LcmBus::create(bus_options);
    if (!coop_bus.ok()) return coop_bus.status();
    node->coop_bus_ = std::move(*coop_bus);
  }
  if (Status s = node->subscribe(); !s.ok()) return s;
  return node;
}

void AgentNode::push(SensorEvent&& event, const std::string& channel, std::size_t capacity,
                     std::shared_ptr<const cvslam::stereo_image_t> image) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    std::size_t& n = inbox_count_[channel];
    if (n >= capacity) {
      ++dropped_[channel];
      return;
    }
    ++n;
    const double t = now();
    last_arrival_s_ = t;
    inbox_.push_back(Inbound{std::move(event), t, std::move(image)});
  }
  inbox_cv_.notify_one();
}

Status AgentNode::subscribe() {
  const int id = o_.id;
  // Sensor streams come from the replay (or a simulator) only.
  auto fromReplay = [this](int32_t sender, const std::string& channel) {
    if (sender == kReplaySenderId) return true;
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    ++rejected_[channel];
    return false;
  };
  // One subscription per sensor stream: from the replay only, converted to a SensorEvent
  // (sensor_convert.h), queued with the stream's capacity; an image pair is queued as it came
  // and decoded by order(), which rejects a pair that does not decode.
  auto sensor = [&](const std::string& channel, std::size_t capacity, auto typed) -> Status {
    using Msg = typename decltype(typed)::type;
    return bus_->subscribe<Msg>(channel, [=](const Msg& m) {
      if (!fromReplay(m.header.agent_id, channel)) return;
      SensorEvent e;
      if constexpr (std::is_same_v<Msg, cvslam::stereo_image_t>) {
        e.type = SensorEventType::kStereoImage;
        e.agent_id = id;
        e.t_us = m.header.utime;
        push(std::move(e), channel, capacity, std::make_shared<const cvslam::stereo_image_t>(m));
        return;
      }
      if (!toSensorEvent(m, id, &e)) {
        std::lock_guard<std::mutex> lock(inbox_mutex_);
        ++rejected_[channel];
        return;
      }
      push(std::move(e), channel, capacity);
    });
  };
  Status s = sensor(channels::imu(id), o_.imu_queue, std::common_type<cvslam::imu_t>{});
  if (s.ok())
    s = sensor(channels::groundTruth(id), o_.imu_queue, std::common_type<cvslam::pose_t>{});
  if (s.ok())
    s = sensor(channels::features(id), o_.frame_queue,
               std::common_type<cvslam::stereo_features_t>{});
  if (s.ok())
    s = sensor(channels::stereo(id), o_.frame_queue, std::common_type<cvslam::stereo_image_t>{});
  if (!s.ok()) return s;
  if (coop_) return coop_->subscribe(coopBus());
  return Status::Ok();
}

Status AgentNode::startPipeline(const AgentFilterSetup& setup) {
  auto agent = AgentPipeline::create(o_.id, setup, calibration_.camera);
  if (!agent.ok()) return agent.status();
  agent_ = std::move(*agent);
  if (images_) agent_->useImages(std::move(*images_), calibration_.rectifier);
  images_.reset();
  if (!o_.out_dir.empty()) {
    if (Status s = recorder_.open(o_.out_dir, o_.id, false); !s.ok()) return s;
  }
  if (coop_) return coop_->onStart(*agent_, coopBus(), o_.filter_name);
  return Status::Ok();
}

Status AgentNode::addImu(const ImuSample& sample) {
  if (Status s = agent_->addImu(sample); !s.ok()) return s;
  if (coop_) coop_->onImu(sample);
  return Status::Ok();
}

Status AgentNode::startUnknownPose(const SensorEvent& e) {
  if (!unknown_start_) {
    std::optional<vision::StereoFrontEnd> front_end;
    if (images_) front_end = images_->frontEnd();  // a copy: shares the detector (one thread)
    unknown_start_ = std::make_unique<UnknownPoseStart>(o_.unknown_pose, calibration_,
                                                        o_.initial_sigma, std::move(front_end));
  }
  UnknownPoseStart& start = *unknown_start_;
  Status s;
  switch (e.type) {
    case SensorEventType::kImu:
      s = start.addImu(e.imu);
      break;
    case SensorEventType::kFeatures:
      s = start.addFeatures(e.features);
      ++before_start_;
      break;
    case SensorEventType::kStereoImage:
      s = start.addImages(e.t_us, e.left, e.right);
      ++before_start_;
      break;
    case SensorEventType::kGroundTruth:
      return Status::Ok();  // recorded once started
  }
  if (!s.ok()) {
    fatal_ = s;  // no start, no estimate: the node stops (run() returns it)
    return Status::Ok();
  }
  if (!start.started()) return Status::Ok();
  if (o_.verbose) std::fprintf(stderr, "cvslam_agent %d: %s\n", o_.id, start.report().c_str());
  if (Status st = startPipeline(start.setup()); !st.ok()) return st;
  for (const ImuSample& sample : start.imuFromStart())
    if (Status st = addImu(sample); !st.ok()) return st;
  unknown_start_.reset();
  return Status::Ok();
}

Status AgentNode::processEvent(SensorEvent& e, double arrival_s) {
  if (!agent_ && o_.start != AgentNodeOptions::Start::kKnown) return startUnknownPose(e);
  if (!agent_ && !start_decided_) {
    // A known initial estimate (scenario) holds only when the data starts there; an agent
    // (re)started in the middle of a run starts at the first ground truth instead.
    start_decided_ = true;
    if (calibration_.setup && e.t_us <= calibration_.setup->t0_us + kLateStartUs) {
      if (Status s = startPipeline(*calibration_.setup); !s.ok()) return s;
    } else if (o_.verbose) {
      std::fprintf(stderr, "cvslam_agent %d: starting at the first ground truth\n", o_.id);
    }
  }
  switch (e.type) {
    case SensorEventType::kImu:
      if (!agent_) {
        if (pre_start_imu_) ++before_start_;
        pre_start_imu_ = e.imu;
        return Status::Ok();
      }
      return addImu(e.imu);
    case SensorEventType::kGroundTruth:
      truth_ = std::make_pair(e.t_us, truthState(e.truth));
      if (world_in_own_) {
        // UAV<N>/GT is the world's truth, and this agent (start unknown) estimates in its own
        // frame: recorded there, as cvslam_run records it. TeamFrame::apply carries a vehicle
        // state between two gravity-aligned frames, here world → own.
        coop::TeamFrame own;
        own.own_in_root = *world_in_own_;
        truth_->second = own.apply(truth_->second);
      }
      if (!agent_) {
        // Thesis §6.3.1: the initial pose is known in the team's frame — or, start unknown
        // (an agent restarted in flight), in its own frame, where its truth is recorded.
        const Vector9d& x = truth_->second;
        const Eigen::Vector3d euler = x.tail<3>();
        const Eigen::Vector3d v_N = rotationBodyToNav<double>(euler) * x.segment<3>(3);
        if (Status s = startPipeline(knownPoseSetup(e.t_us, x.head<3>(), v_N, euler,
                                                    o_.initial_sigma, calibration_.options));
            !s.ok()) {
          return s;
        }
        if (pre_start_imu_ && pre_start_imu_->t_us == e.t_us) {
          if (Status s = addImu(*pre_start_imu_); !s.ok()) return s;
        } else if (pre_start_imu_) {
          ++before_start_;
        }
        pre_start_imu_.reset();
      }
      return Status::Ok();
    case SensorEventType::kFeatures:
    case SensorEventType::kStereoImage:
      break;
  }
  if (!agent_ || e.t_us < agent_->slam().time()) {
    ++before_start_;
    return Status::Ok();
  }
  if (e.type == SensorEventType::kFeatures) {
    e.features.t_us = e.t_us;
    if (Status s = agent_->processFeatures(e.features); !s.ok()) return s;
    ++feature_frames_;
  } else {
    if (!agent_->imagesEnabled()) {
      ++frames_skipped_;
      return Status::Ok();
    }
    if (Status s = agent_->processImages(e.t_us, e.left, e.right); !s.ok()) return s;
    ++image_frames_;
  }
  return afterFrame(arrival_s);
}

Status AgentNode::afterFrame(double arrival_s) {
  const AgentFrame& frame = agent_->lastFrame();
  // Cooperation first (as cvslam_run: the fused estimate is the frame's result), its outbox
  // published before the pose and before the STATUS that lets the replay go on.
  if (coop_) {
    if (Status s = coop_->afterFrame(*agent_, coopBus(),
                                     [this](cvslam::agent_summary_t& m) { fillCounters(m); });
        !s.ok()) {
      return s;
    }
  }
  if ((!coop_ || !coop_->sendsSummary()) &&
      (last_summary_us_ < 0 ||
       frame.t_us - last_summary_us_ >= std::llround(o_.summary_period_s * 1e6))) {
    last_summary_us_ = frame.t_us;
    if (Status s = publishSummary(); !s.ok()) return s;
  }
  // cc: the ground station's estimate of the frame when it came in time, else the agent's own.
  const VehicleEstimate* adopted = coop_ ? coop_->adopted() : nullptr;
  const VisualInertialSlam& slam = agent_->slam();
  cvslam::agent_state_t pose =
      adopted ? agentStateMessage(o_.id, o_.filter_name, frame.t_us, adopted->x_v, adopted->P_v)
              : agentStateMessage(o_.id, o_.filter_name, frame.t_us, slam.vehicleState(),
                                  slam.vehicleCovariance());
  pose.num_landmarks = frame.report.landmarks_in_state;
  pose.num_archived = static_cast<int32_t>(slam.archive().size());
  if (Status s = bus_->publish(channels::pose(o_.id), pose); !s.ok()) return s;
  if (o_.map_period_s > 0.0 &&
      (last_map_us_ < 0 || frame.t_us - last_map_us_ >= std::llround(o_.map_period_s * 1e6))) {
    last_map_us_ = frame.t_us;
    Expected<cvslam::agent_map_t> map = agentMapMessage(o_.id, frame.t_us, slam.map());
    if (!map.ok()) return map.status();
    if (Status s = bus_->publish(channels::agentMap(o_.id), *map); !s.ok()) return s;
  }
  const double latency_ms = (now() - arrival_s) * 1e3;
  latencies_ms_.push_back(latency_ms);
  if (recorder_.isOpen()) {
    const Vector9d* truth = nullptr;
    if (truth_ && std::llabs(truth_->first - frame.t_us) <= kTruthToleranceUs)
      truth = &truth_->second;
    if (Status s = recorder_.addFrame(*agent_, truth, latency_ms, adopted); !s.ok()) return s;
    int root = 0;
    Vector9d x_team;
    if (coop_ && coop_->teamState(slam.vehicleState().head<9>(), &root, &x_team))
      if (Status s =
              recorder_.writer().addTeamState(static_cast<double>(frame.t_us) * 1e-6, root, x_team);
          !s.ok())
        return s;
  }
  return Status::Ok();
}

void AgentNode::fillCounters(cvslam::agent_summary_t& msg) {
  if (last_counters_us_ >= 0 &&
      msg.header.utime - last_counters_us_ < std::llround(o_.counters_period_s * 1e6))
    return;
  last_counters_us_ = msg.header.utime;
  std::map<std::string, ChannelCounters> by_channel;
  for (const ChannelCounters& c : allCounters()) {
    ChannelCounters& sum = by_channel[c.channel];
    sum.received += c.received;
    sum.dropped += c.dropped + c.seq_gaps;  // LCM's own queue losses show as gaps
    sum.invalid += c.invalid;
  }
  std::lock_guard<std::mutex> lock(inbox_mutex_);
  for (auto& [channel, c] : by_channel) {
    auto d = dropped_.find(channel);
    auto r = rejected_.find(channel);
    const int64_t dropped = d == dropped_.end() ? 0 : d->second;
    const int64_t rejected = r == rejected_.end() ? 0 : r->second;
    msg.channel.push_back(channel);
    msg.received.push_back(c.received - dropped - rejected);
    msg.dropped.push_back(c.dropped + dropped);
    msg.invalid.push_back(c.invalid + rejected);
  }
}

Status AgentNode::publishSummary() {
  cvslam::agent_summary_t m{};
  m.header.utime = agent_ ? agent_->lastFrame().t_us : 0;
  m.header.agent_id = o_.id;
  m.mode = o_.mode;
  m.boot_id = o_.boot_id;
  // The ellipsoid of the landmarks observed now (thesis §6.6.2), for the team's display.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
  int n = 0;
  if (agent_ && agent_->lastFrame().observations != nullptr) {
    const VisualInertialSlam& slam = agent_->slam();
    for (const StereoObservation& o : agent_->lastFrame().observations->observations) {
      if (o.landmark_id < 0) continue;
      const StateVariable* v =
          slam.state().find(VariableKey::landmark(static_cast<uint64_t>(o.landmark_id)));
      if (v == nullptr) continue;
      const Eigen::Vector3d p = slam.state().value(*v);
      sum += p;
      sq += p.cwiseProduct(p);
      ++n;
    }
  }
  const Eigen::Vector3d mean = n > 0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d var =
      n > 0 ? Eigen::Vector3d((sq / n - mean.cwiseProduct(mean)).cwiseMax(0.0))
            : Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    m.ellipsoid_mean[i] = mean(i);
    m.ellipsoid_std[i] = std::sqrt(var(i));
  }
  m.num_features = n;
  m.vehicle_cov_trace =
      agent_ ? agent_->slam().vehicleCovariance().topLeftCorner<3, 3>().trace() : 0.0;
  fillCounters(m);
  return coopBus().publish(channels::teamSummary(), m);
}

double AgentNode::lastArrival() const {
  std::lock_guard<std::mutex> lock(inbox_mutex_);
  return std::max(last_arrival_s_, start_s_);
}

Status AgentNode::publishStatus() {
  cvslam::status_t m{};
  m.header.utime = std::max<int64_t>(processed_us_, 0);
  m.header.agent_id = o_.id;
  // An IMU or GT sample at t does not finish t: the frame taken at t comes after it. Reporting
  // t then would let a lockstep replay publish the next epoch before this agent has processed
  // (and, in DC mode, sent the cooperation messages of) its frame at t. So IMU/GT progress
  // counts up to t − 1 µs until the sensors have been quiet for a status period (an instant
  // without a frame for this agent, or the end of the data).
  const bool unfinished = frame_may_follow_ && now() - lastArrival() < o_.status_period_s;
  m.processed_utime = unfinished ? processed_us_ - 1 : processed_us_;
  m.health = errors_ > 0 || (coop_ && coop_->degraded()) ? cvslam::status_t::HEALTH_DEGRADED
                                                         : cvslam::status_t::HEALTH_OK;
  m.message = coop_ ? coop_->statusText() : std::string();
  if (!last_error_.empty()) m.message += (m.message.empty() ? "" : "; ") + last_error_;
  return bus_->publish(channels::status(o_.id), m);
}

Status AgentNode::flushRecord(bool final) {
  if (!recorder_.isOpen()) return Status::Ok();
  AgentRunWriter& w = recorder_.writer();
  std::map<std::string, int64_t> bytes = bus_->bytesPublishedByChannel();
  if (coop_bus_)
    for (const auto& [channel, n] : coop_bus_->bytesPublishedByChannel()) bytes[channel] += n;
  std::map<std::string, int64_t> by_stream;
  for (const auto& [channel, n] : bytes) {
    if (auto id = parseChannel(channel)) by_stream[streamName(id->stream)] += n;
  }
  int64_t coop = 0;
  for (Stream s : kCoopStreams) {
    by_stream.emplace(streamName(s), 0);
    coop += by_stream[streamName(s)];
  }
  by_stream["cooperation"] = coop;
  for (const auto& [stream, n] : by_stream) w.setBytesSent(stream, n);
  w.setBytesSentTotal(coop);
  if (agent_) {
    // The true landmarks are known only for a simulated world with feature-level frames
    // (named by true id); image frames name them by visual word.
    LandmarkTruthFn truth;
    if (feature_frames_ > 0 && image_frames_ == 0) truth = calibration_.landmark_truth;
    if (Status s = recorder_.writeMap(agent_->slam(), truth); !s.ok()) return s;
  }
  return final ? recorder_.close() : recorder_.flush();
}

void AgentNode::order(std::vector<Inbound>& batch) {
  for (Inbound& in : batch) {
    if (in.image != nullptr && !fromStereoMessage(*in.image, in.event.left, in.event.right).ok()) {
      std::lock_guard<std::mutex> lock(inbox_mutex_);
      ++rejected_[channels::stereo(o_.id)];
      continue;
    }
    if (!orderer_.push(std::move(in.event), in.arrival_s)) ++late_;
  }
  batch.clear();
}

Status AgentNode::run(const std::atomic<bool>& stop) {
  if (Status s = bus_->start(); !s.ok()) return s;
  if (coop_bus_)
    if (Status s = coop_bus_->start(); !s.ok()) return s;
  start_s_ = now();
  double last_status = -1e300, last_flush = now();
  std::vector<Inbound> batch;
  SensorEvent event;
  Status failure;
  while (!stop) {
    {
      std::unique_lock<std::mutex> lock(inbox_mutex_);
      inbox_cv_.wait_for(lock, std::chrono::milliseconds(10), [this] { return !inbox_.empty(); });
      batch.swap(inbox_);
      inbox_count_.clear();
    }
    // Cooperation after the sensor inbox: whatever arrived before these sensor messages is
    // handed over now (lockstep: the peers' outboxes of the previous epoch).
    if (coop_) coop_->drainInbound();
    order(batch);
    bool progressed = false;
    double arrival = 0.0;
    while (orderer_.pop(now(), false, &event, &arrival)) {
      progressed = true;
      handle(event, arrival);
    }
    if (!fatal_.ok()) {
      bus_->stop();
      if (coop_bus_) coop_bus_->stop();
      return fatal_;
    }
    const double t = now();
    if (progressed || t - last_status >= o_.status_period_s) {
      last_status = t;
      if (Status s = publishStatus(); !s.ok()) return s;
    }
    if (t - last_flush >= o_.flush_period_s) {
      last_flush = t;
      if (Status s = flushRecord(false); !s.ok()) return s;
    }
    const double last_arrival = lastArrival();
    bool inbox_empty = true;
    {
      std::lock_guard<std::mutex> lock(inbox_mutex_);
      inbox_empty = inbox_.empty();
    }
    // Idle: nothing arrived for idle_exit_s and nothing waits (a slow agent working through a
    // backlog is not idle).
    if (o_.idle_exit_s > 0.0 && inbox_empty && orderer_.size() == 0 &&
        t - last_arrival >= o_.idle_exit_s) {
      if (o_.verbose)
        std::fprintf(stderr, "cvslam_agent %d: no sensor data for %.1f s, exiting\n", o_.id,
                     o_.idle_exit_s);
      break;
    }
  }
  // What is left, in order (shutdown or end of data).
  bus_->stop();
  if (coop_bus_) coop_bus_->stop();
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    batch.swap(inbox_);
  }
  if (coop_) coop_->drainInbound();
  order(batch);
  double arrival = 0.0;
  while (orderer_.pop(now(), true, &event, &arrival)) handle(event, arrival);
  if (Status s = publishStatus(); !s.ok()) return s;
  return flushRecord(true);
}

void AgentNode::handle(SensorEvent& event, double arrival_s) {
  Status s = processEvent(event, arrival_s);
  processed_us_ = std::max(processed_us_, event.t_us);
  frame_may_follow_ =
      event.type == SensorEventType::kImu || event.type == SensorEventType::kGroundTruth;
  if (!s.ok()) {
    ++errors_;
    last_error_ = s.message();
    if (o_.verbose || errors_ <= 3)
      std::fprintf(stderr, "cvslam_agent %d: %s\n", o_.id, s.message().c_str());
  }
}

std::vector<ChannelCounters> AgentNode::allCounters() const {
  std::vector<ChannelCounters> all = bus_->counters();
  if (coop_bus_)
    for (ChannelCounters& c : coop_bus_->counters()) all.push_back(std::move(c));
  return all;
}

std::string AgentNode::report() const {
  char buf[512];
  std::vector<double> l = latencies_ms_;
  std::sort(l.begin(), l.end());
  auto pct = [&](double q) {
    return l.empty() ? 0.0 : l[std::min(l.size() - 1, static_cast<std::size_t>(q * l.size()))];
  };
  int64_t dropped = 0, invalid = 0, gaps = 0, unsigned_msgs = 0, forged = 0, replayed = 0;
  for (const ChannelCounters& c : allCounters()) {
    dropped += c.dropped;
    invalid += c.invalid;
    gaps += c.seq_gaps;
    unsigned_msgs += c.unsigned_msgs;
    forged += c.forged;
    replayed += c.replayed;
  }
  for (const auto& [ch, n] : dropped_) dropped += n;
  for (const auto& [ch, n] : rejected_) invalid += n;
  std::snprintf(buf, sizeof(buf),
                "UAV%d: %ld frames, latency median %.1f ms, p95 %.1f ms, max %.1f ms; messages "
                "dropped %lld, seq gaps %lld, invalid %lld, late %lld, before start %lld, "
                "errors %lld",
                o_.id, agent_ ? agent_->frames() : 0L, pct(0.5), pct(0.95),
                l.empty() ? 0.0 : l.back(), static_cast<long long>(dropped),
                static_cast<long long>(gaps), static_cast<long long>(invalid),
                static_cast<long long>(late_), static_cast<long long>(before_start_),
                static_cast<long long>(errors_));
  std::string r = buf;
  if (recorder_.isOpen()) {
    const std::string stages = stageTimesLine(recorder_.writer().stats());
    if (!stages.empty()) r += "\n  " + stages;
  }
  if (o_.auth_key) {
    std::snprintf(buf, sizeof(buf),
                  "; authentication refused: unsigned %lld, forged %lld, replayed %lld",
                  static_cast<long long>(unsigned_msgs), static_cast<long long>(forged),
                  static_cast<long long>(replayed));
    r += buf;
  }
  if (coop_) r += "\n  " + coop_->report();
  return r;
}

}  // namespace cvslam::transport
