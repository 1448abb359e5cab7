#include "dc_team_link.h"

#include "cvslam/coop/coop_log.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/coop_convert.h"

namespace cvslam {

namespace {
constexpr int64_t kBootIdBase = 1000;  // deterministic boot ids for in-process runs
}  // namespace

DcTeamLink::DcTeamLink(const coop::DcCooperationOptions& options,
                       const std::vector<int>& agent_ids) {
  for (int id : agent_ids)
    agents_[id] = std::make_unique<coop::DcCooperation>(id, options, kBootIdBase + id);
}

Status DcTeamLink::open(const std::string& run_dir) {
  for (const auto& [id, a] : agents_) {
    const std::string path = agentDir(run_dir, id) + "/coop.csv";
    std::ofstream& f = csv_[id];
    f.open(path, std::ios::trunc);
    if (!f) return Status::Error("cannot write " + path);
    f << coop::coopCsvHeader();
  }
  return Status::Ok();
}

template <typename Msg, typename Deliver>
Status DcTeamLink::send(int from, const std::string& stream, Msg msg, AgentRunWriter* writer,
                        const Deliver& deliver) {
  Expected<std::vector<uint8_t>> bytes = transport::encodeMessage(msg);
  if (!bytes.ok())
    return Status::Error("UAV" + std::to_string(from) + ": " + bytes.status().message());
  const auto n = static_cast<int64_t>(bytes->size());
  bytes_[from][stream] += n;
  if (writer != nullptr) writer->addBytesSent(stream, n);
  Expected<Msg> back = transport::decodeMessage<Msg>(bytes->data(), bytes->size());
  if (!back.ok()) {
    ++decode_failures_;
    return Status::Ok();  // a receiver drops what it cannot decode
  }
  deliver(*back);
  return Status::Ok();
}

Status DcTeamLink::afterFrame(const SimulatedFrame& f, AgentRunWriter* writer) {
  auto it = agents_.find(f.agent_id);
  if (it == agents_.end() || f.mutable_slam == nullptr)
    return Status::Error("dc: unknown agent " + std::to_string(f.agent_id));
  coop::DcCooperation& self = *it->second;
  StereoFrameObservations frame;
  frame.t_us = f.t_us;  // DcCooperation needs the frame time only
  coop::CoopOutbox box;
  if (Status s = self.afterFrame(frame, *f.mutable_slam, &box); !s.ok()) return s;

  std::ofstream& csv = csv_[f.agent_id];
  for (const coop::CoopEvent& e : self.takeEvents()) coop::writeCoopCsvRow(csv, e);

  const int from = f.agent_id;
  return transport::forEachOutboxMessage(
      box, from, [&](const std::string&, transport::Stream stream, int to, auto& m) -> Status {
        return send(from, transport::streamName(stream), m, writer,
                    [&](const auto& msg) { deliver(from, to, msg); });
      });
}

// Broadcasts reach every other agent, directed messages their addressee.
void DcTeamLink::deliver(int from, int, const cvslam::agent_summary_t& msg) {
  for (auto& [id, a] : agents_)
    if (id != from) a->onSummary(transport::fromMessage(msg));
}

void DcTeamLink::deliver(int from, int, const cvslam::feature_index_t& msg) {
  for (auto& [id, a] : agents_)
    if (id != from) a->onIndex(transport::fromMessage(msg));
}

void DcTeamLink::deliver(int, int to, const cvslam::shared_request_t& msg) {
  if (auto peer = agents_.find(to); peer != agents_.end())
    peer->second->onRequest(transport::fromMessage(msg, to));
}

void DcTeamLink::deliver(int, int to, const cvslam::shared_landmarks_t& msg) {
  if (auto peer = agents_.find(to); peer != agents_.end())
    peer->second->onShared(transport::fromMessage(msg, to));
}

void DcTeamLink::printSummary(std::FILE* out, double duration_s) const {
  std::fprintf(out, "  cooperation (DC, %s CI):\n",
               coop::ciMethodName(agents_.begin()->second->options().ci_method).c_str());
  for (const auto& [id, a] : agents_) {
    const coop::DcCooperationStatistics& s = a->statistics();
    int64_t total = 0;
    std::string per_stream;
    if (auto b = bytes_.find(id); b != bytes_.end()) {
      for (const auto& [stream, n] : b->second) {
        total += n;
        per_stream += " " + stream + " " +
                      std::to_string(static_cast<int64_t>(static_cast<double>(n) / duration_s));
      }
    }
    std::fprintf(
        out,
        "    UAV%d: %lld exchanges, %lld landmarks fused; requests sent %lld, answered "
        "%lld; rejected: gate %lld, descriptor %lld, not in state %lld, stale %lld, "
        "duplicate %lld, reordered %lld, invalid %lld; request timeouts %lld; "
        "%.0f B/s (%s )\n",
        id, static_cast<long long>(s.exchanges_completed),
        static_cast<long long>(s.landmarks_fused), static_cast<long long>(s.requests_sent),
        static_cast<long long>(s.shared_sent), static_cast<long long>(s.rejected_gate),
        static_cast<long long>(s.rejected_descriptor),
        static_cast<long long>(s.shared_not_in_state), static_cast<long long>(s.rejected_stale),
        static_cast<long long>(s.rejected_duplicate), static_cast<long long>(s.rejected_reordered),
        static_cast<long long>(s.rejected_invalid), static_cast<long long>(s.request_timeouts),
        static_cast<double>(total) / duration_s, per_stream.c_str());
  }
  if (decode_failures_ > 0)
    std::fprintf(out, "    %lld messages failed to decode\n",
                 static_cast<long long>(decode_failures_));
}

}  // namespace cvslam
