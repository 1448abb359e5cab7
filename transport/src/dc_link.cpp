#include "cvslam/lcm/dc_link.h"

#include <cstdio>
#include <filesystem>

#include "cvslam/coop/coop_log.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/coop_convert.h"

namespace cvslam::transport {
namespace {

const coop::CoopHeader& headerOf(
    const std::variant<coop::CoopSummary, coop::FeatureIndexList, coop::SharedRequest,
                       coop::SharedLandmarks>& m) {
  return std::visit([](const auto& x) -> const coop::CoopHeader& { return x.header; }, m);
}

}  // namespace

DcLink::DcLink(int self_id, const coop::DcCooperationOptions& options, int64_t boot_id,
               std::string out_dir)
    : self_(self_id), dc_(self_id, options, boot_id), out_dir_(std::move(out_dir)) {}

void DcLink::receive(Message m) {
  // Our own broadcasts come back over multicast: not a peer's message.
  if (headerOf(m).agent_id == self_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  arrived_.push_back(std::move(m));
}

Status DcLink::subscribe(LcmBus& bus) {
  const int self = self_;
  Status s = bus.subscribe<cvslam::agent_summary_t>(
      channels::teamSummary(),
      [this](const cvslam::agent_summary_t& m) { receive(fromMessage(m)); });
  if (!s.ok()) return s;
  s = bus.subscribe<cvslam::feature_index_t>(
      allAgentsPattern(Stream::kIndex),
      [this](const cvslam::feature_index_t& m) { receive(fromMessage(m)); });
  if (!s.ok()) return s;
  s = bus.subscribe<cvslam::shared_request_t>(
      channels::sharedRequest(self),
      [this, self](const cvslam::shared_request_t& m) { receive(fromMessage(m, self)); });
  if (!s.ok()) return s;
  return bus.subscribe<cvslam::shared_landmarks_t>(
      channels::shared(self),
      [this, self](const cvslam::shared_landmarks_t& m) { receive(fromMessage(m, self)); });
}

void DcLink::drainInbound() {
  std::vector<Message> batch;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    batch.swap(arrived_);
  }
  for (Message& m : batch) {
    const coop::CoopHeader& h = headerOf(m);
    Key key{h.t_us, h.agent_id, m.index(), h.seq, arrivals_++};
    pending_.emplace(key, std::move(m));
  }
}

Status DcLink::afterFrame(AgentPipeline& agent, LcmBus& bus,
                          const std::function<void(cvslam::agent_summary_t&)>& fill_counters) {
  const int64_t t_us = agent.lastFrame().t_us;
  // Hand over what this frame may apply (older than the frame), in cvslam_run's order.
  while (!pending_.empty() && std::get<0>(pending_.begin()->first) < t_us) {
    Message m = std::move(pending_.begin()->second);
    pending_.erase(pending_.begin());
    const bool accepted = std::visit(
        [this](auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, coop::CoopSummary>) return dc_.onSummary(x);
          if constexpr (std::is_same_v<T, coop::FeatureIndexList>) return dc_.onIndex(x);
          if constexpr (std::is_same_v<T, coop::SharedRequest>) return dc_.onRequest(x);
          if constexpr (std::is_same_v<T, coop::SharedLandmarks>) return dc_.onShared(x);
        },
        m);
    if (!accepted) ++refused_;
  }
  StereoFrameObservations frame;
  frame.t_us = t_us;  // DcCooperation needs the frame time only (as cvslam_run gives it)
  coop::CoopOutbox box;
  if (Status s = dc_.afterFrame(frame, agent.slam(), &box); !s.ok()) return s;
  if (Status s = writeEvents(); !s.ok()) return s;

  return forEachOutboxMessage(
      box, self_, [&](const std::string& channel, Stream, int, auto& m) -> Status {
        if constexpr (std::is_same_v<std::decay_t<decltype(m)>, cvslam::agent_summary_t>) {
          fill_counters(m);
        }
        return bus.publish(channel, m);
      });
}

Status DcLink::writeEvents() {
  std::vector<coop::CoopEvent> events = dc_.takeEvents();
  if (out_dir_.empty()) return Status::Ok();
  if (!csv_.is_open()) {
    const std::string dir = agentDir(out_dir_, self_);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    csv_.open(dir + "/coop.csv", std::ios::trunc);
    if (!csv_) return Status::Error("cannot write " + dir + "/coop.csv");
    csv_ << coop::coopCsvHeader();
  }
  for (const coop::CoopEvent& e : events) coop::writeCoopCsvRow(csv_, e);
  csv_.flush();
  return Status::Ok();
}

std::string DcLink::report() const {
  const coop::DcCooperationStatistics& s = dc_.statistics();
  char buf[640];
  std::snprintf(
      buf, sizeof(buf),
      "cooperation: peers %d, exchanges %lld, landmarks fused %lld, requests sent %lld, "
      "shared sent %lld; rejected: invalid %lld, gate %lld, descriptor %lld, stale "
      "%lld, duplicate %lld, reordered %lld, unknown peer %lld; peer restarts %lld, "
      "peer timeouts %lld, request timeouts %lld",
      s.peers_known, static_cast<long long>(s.exchanges_completed),
      static_cast<long long>(s.landmarks_fused), static_cast<long long>(s.requests_sent),
      static_cast<long long>(s.shared_sent), static_cast<long long>(s.rejected_invalid),
      static_cast<long long>(s.rejected_gate), static_cast<long long>(s.rejected_descriptor),
      static_cast<long long>(s.rejected_stale), static_cast<long long>(s.rejected_duplicate),
      static_cast<long long>(s.rejected_reordered), static_cast<long long>(s.rejected_unknown_peer),
      static_cast<long long>(s.peer_restarts), static_cast<long long>(s.peer_timeouts),
      static_cast<long long>(s.request_timeouts));
  return buf;
}

}  // namespace cvslam::transport
