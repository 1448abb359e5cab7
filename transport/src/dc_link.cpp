#include "cvslam/lcm/dc_link.h"

#include <type_traits>
#include <variant>

#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/coop_convert.h"

namespace cvslam::transport {

DcLink::DcLink(int self_id, const coop::DcCooperationOptions& options, int64_t boot_id,
               std::string out_dir)
    : core_(self_id, options, boot_id), out_dir_(std::move(out_dir)) {}

void DcLink::receive(coop::CoopMessage m) {
  std::lock_guard<std::mutex> lock(mutex_);
  const int sender = std::visit([](const auto& msg) { return msg.header.agent_id; }, m);
  if (sender != core_.id()) links_.add(m);
  arrived_.push_back(std::move(m));
}

Status DcLink::subscribe(LcmBus& bus) {
  const int self = core_.id();
  auto handler = [this, self](const auto& m) { receive(toCoopMessage(m, self)); };
  Status s = bus.subscribe<cvslam::agent_summary_t>(channels::teamSummary(), handler);
  if (!s.ok()) return s;
  s = bus.subscribe<cvslam::feature_index_t>(allAgentsPattern(Stream::kIndex), handler);
  if (!s.ok()) return s;
  s = bus.subscribe<cvslam::shared_request_t>(channels::sharedRequest(self), handler);
  if (!s.ok()) return s;
  return bus.subscribe<cvslam::shared_landmarks2_t>(channels::shared(self), handler);
}

void DcLink::drainInbound() {
  std::vector<coop::CoopMessage> batch;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    batch.swap(arrived_);
  }
  for (coop::CoopMessage& m : batch) core_.receive(std::move(m));
}

Status DcLink::afterFrame(AgentPipeline& agent, LcmBus& bus,
                          const std::function<void(cvslam::agent_summary_t&)>& fill_counters) {
  if (!out_dir_.empty() && !log_open_) {
    if (Status s = core_.openLog(out_dir_); !s.ok()) return s;
    log_open_ = true;
  }
  const int64_t t_us = agent.lastFrame().t_us;
  if (first_frame_us_ < 0) first_frame_us_ = t_us;
  last_frame_us_ = t_us;
  coop::CoopOutbox box;
  StereoFrameObservations none;
  none.t_us = t_us;
  const StereoFrameObservations* frame = agent.lastFrame().observations;
  if (Status s = core_.afterFrame(frame != nullptr ? *frame : none, agent.slam(), &box); !s.ok())
    return s;
  // A message the network refuses (sendto fails) is lost like one dropped on the way: the
  // rest of the frame's messages still go out; the first failure is reported.
  Status first_failure;
  Status s = forEachOutboxMessage(
      box, core_.id(), [&](const std::string& channel, Stream stream, int, auto& m) -> Status {
        if constexpr (std::is_same_v<std::decay_t<decltype(m)>, cvslam::agent_summary_t>) {
          fill_counters(m);
        }
        if (Status p = bus.publish(channel, m); !p.ok()) {
          if (first_failure.ok()) first_failure = p;
          return Status::Ok();
        }
        core_.countSent(streamName(stream), m.getEncodedSize());  // finalized by publish
        return Status::Ok();
      });
  return s.ok() ? first_failure : s;
}

std::string DcLink::statusText() const {
  std::string peers;
  for (int id : core_.cooperation().peers())
    peers += (peers.empty() ? "" : ",") + std::to_string(id);
  const coop::DcCooperationStatistics& s = core_.cooperation().statistics();
  std::lock_guard<std::mutex> lock(mutex_);
  return "peers " + (peers.empty() ? std::string("none") : peers) + "; timeouts " +
         std::to_string(s.peer_timeouts) + "; restarts " + std::to_string(s.peer_restarts) +
         "; links " + links_.text(last_frame_us_);
}

std::string DcLink::report() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return core_.report(static_cast<double>(last_frame_us_ - first_frame_us_) * 1e-6) +
         "; links (received/expected) " + links_.text(last_frame_us_);
}

}  // namespace cvslam::transport
