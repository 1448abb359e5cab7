#include "cvslam/lcm/view_node.h"

#include <chrono>
#include <cmath>

#include "covariance_triangle.h"
#include "cvslam/lcm/cc_convert.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {
namespace {

double seconds(int64_t t_us) {
  return static_cast<double>(t_us) * 1e-6;
}

// The position block and heading of a vehicle estimate ([X Y Z U V W φ θ ψ ...] on the wire,
// agent_state_t.lcm; decoded by cc_convert.h).
view::ViewEstimate viewEstimate(const VehicleEstimate& v, int agent_id) {
  view::ViewEstimate e;
  e.agent_id = agent_id;
  e.t = seconds(v.t_us);
  e.p = v.x_v.head<3>();
  e.P = v.P_v.topLeftCorner<3, 3>();
  e.yaw = v.x_v(8);
  return e;
}

std::vector<view::ViewLandmark> landmarksOf(const cvslam::agent_map_t& m) {
  std::vector<view::ViewLandmark> out(m.id.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].p = Eigen::Vector3f(m.position[i][0], m.position[i][1], m.position[i][2]);
    out[i].std_m = m.position_std[i];
    out[i].active = m.active[i] != 0;
  }
  return out;
}

std::vector<view::ViewLandmark> landmarksOf(const cvslam::map_t& m) {
  std::vector<view::ViewLandmark> out(m.index.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto& p = m.position[i];
    out[i].p = Eigen::Vector3d(p[0], p[1], p[2]).cast<float>();
    const double trace = fromUpperTriangle(m.covariance[i]).trace();
    out[i].std_m = static_cast<float>(std::sqrt(std::max(0.0, trace / 3.0)));
    out[i].active = true;
  }
  return out;
}

}  // namespace

ViewNode::ViewNode(const ViewNodeOptions& options) : o_(options), view_(options.view) {}

Expected<std::unique_ptr<ViewNode>> ViewNode::create(const ViewNodeOptions& options) {
  if (options.max_agent_id < 1) return Status::Error("max_agent_id must be >= 1");
  std::unique_ptr<ViewNode> node(new ViewNode(options));
  BusOptions bus;
  bus.url = options.url;
  bus.auth_key = options.auth_key;
  ViewNode* self = node.get();
  bus.receive.on_error = [self](const std::string& channel, const Status&) {
    self->locked([&] { self->view_.countMalformed(channel); });
  };
  Expected<std::unique_ptr<LcmBus>> b = LcmBus::create(bus);
  if (!b.ok()) return b.status();
  node->bus_ = std::move(*b);
  if (Status s = node->subscribe(); !s.ok()) return s;
  return node;
}

double ViewNode::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <typename Fn>
void ViewNode::locked(Fn&& fn) {
  std::lock_guard<std::mutex> lock(mutex_);
  view_.countMessage();
  fn();
}

Status ViewNode::subscribe() {
  LcmBus& bus = *bus_;
  // Messages of every agent, the sender in the header.
  Status s = bus.subscribe<cvslam::agent_state_t>(
      allAgentsPattern(Stream::kPose), [this](const cvslam::agent_state_t& m) {
        view::ViewEstimate e = viewEstimate(estimateOf(m), m.header.agent_id);
        e.landmarks_active = m.num_landmarks;
        e.landmarks_archived = m.num_archived;
        const double wall = now();
        locked([&] { view_.addEstimate(e, wall); });
      });
  if (s.ok())
    s = bus.subscribe<cvslam::agent_map_t>(
        allAgentsPattern(Stream::kMap), [this](const cvslam::agent_map_t& m) {
          std::vector<view::ViewLandmark> map = landmarksOf(m);
          locked([&] { view_.setMap(m.header.agent_id, seconds(m.header.utime), std::move(map)); });
        });
  if (s.ok())
    s = bus.subscribe<cvslam::status_t>(
        allAgentsPattern(Stream::kStatus), [this](const cvslam::status_t& m) {
          // The replay (−1) reports lockstep progress only.
          if (m.header.agent_id < 0) return;
          locked([&] { view_.setStatus(m.header.agent_id, m.health, m.message); });
        });
  if (s.ok())
    s = bus.subscribe<cvslam::map_t>(channels::gsMap(), [this](const cvslam::map_t& m) {
      std::vector<view::ViewLandmark> map = landmarksOf(m);
      locked([&] { view_.setJointMap(seconds(m.header.utime), std::move(map)); });
    });
  if (s.ok())
    s = bus.subscribe<cvslam::agent_summary_t>(
        channels::teamSummary(), [this](const cvslam::agent_summary_t& m) {
          const std::size_t bytes = static_cast<std::size_t>(m.getEncodedSize());
          const double wall = now();
          locked([&] {
            view_.setAgentInfo(m.header.agent_id, m.mode, m.boot_id);
            view_.addTraffic(m.header.agent_id, bytes, wall);
          });
        });
  if (s.ok())
    s = bus.subscribe<cvslam::feature_index_t>(
        allAgentsPattern(Stream::kIndex), [this](const cvslam::feature_index_t& m) {
          const std::size_t bytes = static_cast<std::size_t>(m.getEncodedSize());
          const double wall = now();
          locked([&] { view_.addTraffic(m.header.agent_id, bytes, wall); });
        });
  if (s.ok())
    s = bus.subscribe<cvslam::observation_batch_t>(
        allAgentsPattern(Stream::kObs), [this](const cvslam::observation_batch_t& m) {
          const std::size_t bytes = static_cast<std::size_t>(m.getEncodedSize());
          const double wall = now();
          locked([&] {
            view_.addTraffic(m.header.agent_id, bytes, wall);
            view_.addLink(m.header.agent_id, 0, seconds(m.header.utime),
                          view::LinkKind::kObservations);
          });
        });
  // Directed messages and sensor streams: the UAV is only in the channel name (sensor data
  // come from the replay, agent_id −1), so one subscription per id.
  for (int j = 1; s.ok() && j <= o_.max_agent_id; ++j) {
    s = bus.subscribe<cvslam::shared_request_t>(
        channels::sharedRequest(j), [this, j](const cvslam::shared_request_t& m) {
          const std::size_t bytes = static_cast<std::size_t>(m.getEncodedSize());
          const double wall = now();
          locked([&] {
            view_.addTraffic(m.header.agent_id, bytes, wall);
            view_.addLink(m.header.agent_id, j, seconds(m.header.utime), view::LinkKind::kRequest);
          });
        });
    if (s.ok())
      s = bus.subscribe<cvslam::shared_landmarks2_t>(
          channels::shared(j), [this, j](const cvslam::shared_landmarks2_t& m) {
            const std::size_t bytes = static_cast<std::size_t>(m.getEncodedSize());
            const double wall = now();
            locked([&] {
              view_.addTraffic(m.header.agent_id, bytes, wall);
              view_.addLink(m.header.agent_id, j, seconds(m.header.utime),
                            view::LinkKind::kLandmarks);
            });
          });
    if (s.ok())
      s = bus.subscribe<cvslam::gs_state_t>(
          channels::gsState(j), [this, j](const cvslam::gs_state_t& m) {
            const view::ViewEstimate e = viewEstimate(fromMessage(m), j);
            locked([&] { view_.addGroundStationEstimate(e); });
          });
    if (s.ok())
      s = bus.subscribe<cvslam::pose_t>(
          channels::groundTruth(j), [this, j](const cvslam::pose_t& m) {
            const Eigen::Vector3d p(m.position[0], m.position[1], m.position[2]);
            locked([&] { view_.addTruth(j, seconds(m.header.utime), p); });
          });
    if (!o_.latency) continue;
    if (s.ok())
      s = bus.subscribe<cvslam::stereo_features_t>(
          channels::features(j), [this, j](const cvslam::stereo_features_t& m) {
            const double wall = now();
            locked([&] { view_.addFrameArrival(j, seconds(m.header.utime), wall); });
          });
    if (s.ok())
      s = bus.subscribe<cvslam::stereo_image_t>(
          channels::stereo(j), [this, j](const cvslam::stereo_image_t& m) {
            const double wall = now();
            locked([&] { view_.addFrameArrival(j, seconds(m.header.utime), wall); });
          });
  }
  return s;
}

Status ViewNode::start() {
  return bus_->start();
}

void ViewNode::stop() {
  bus_->stop();
}

Json ViewNode::delta(view::ViewCursor& cursor) {
  const double wall = now();
  std::lock_guard<std::mutex> lock(mutex_);
  return view_.delta(cursor, wall);
}

int64_t ViewNode::malformed() {
  std::lock_guard<std::mutex> lock(mutex_);
  return view_.malformed();
}

int64_t ViewNode::messages() {
  std::lock_guard<std::mutex> lock(mutex_);
  return view_.messages();
}

}  // namespace cvslam::transport
