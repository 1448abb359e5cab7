#include "cvslam/coop/dc_link_core.h"

#include <cstdio>
#include <filesystem>
#include <type_traits>
#include <vector>

#include "cvslam/coop/coop_log.h"
#include "cvslam/io/run_record.h"

namespace cvslam::coop {
namespace {

const CoopHeader& headerOf(const CoopMessage& m) {
  return std::visit([](const auto& x) -> const CoopHeader& { return x.header; }, m);
}

long long ll(int64_t x) {
  return static_cast<long long>(x);
}

}  // namespace

DcLinkCore::DcLinkCore(int self_id, const DcCooperationOptions& options, int64_t boot_id)
    : dc_(self_id, options, boot_id) {}

Status DcLinkCore::openLog(const std::string& run_dir) {
  const std::string dir = agentDir(run_dir, id());
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  log_.open(dir + "/coop.csv", std::ios::trunc);
  if (!log_) return Status::Error("cannot write " + dir + "/coop.csv");
  log_ << coopCsvHeader();
  log_dir_ = dir;
  return dc_.options().frames_given ? Status::Ok() : openRelationsLog();
}

Status DcLinkCore::openRelationsLog() {
  relations_log_.open(log_dir_ + "/relations.csv", std::ios::trunc);
  if (!relations_log_) return Status::Error("cannot write " + log_dir_ + "/relations.csv");
  relations_log_ << relationsCsvHeader();
  return Status::Ok();
}

void DcLinkCore::receive(CoopMessage message) {
  const CoopHeader& h = headerOf(message);
  // Our own broadcasts come back over multicast: not a peer's message.
  if (h.agent_id == id()) return;
  Key key{h.t_us, h.agent_id, message.index(), h.seq, arrivals_++};
  pending_.emplace(key, std::move(message));
}

Status DcLinkCore::afterFrame(const StereoFrameObservations& frame, VisualInertialSlam& slam,
                              CoopOutbox* out) {
  const int64_t t_us = frame.t_us;
  while (!pending_.empty() && std::get<0>(pending_.begin()->first) < t_us) {
    const bool accepted = std::visit(
        [this](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, CoopSummary>) return dc_.onSummary(x);
          if constexpr (std::is_same_v<T, FeatureIndexList>) return dc_.onIndex(x);
          if constexpr (std::is_same_v<T, SharedRequest>) return dc_.onRequest(x);
          if constexpr (std::is_same_v<T, SharedLandmarks>) return dc_.onShared(x);
        },
        pending_.begin()->second);
    if (!accepted) ++refused_;
    pending_.erase(pending_.begin());
  }
  if (Status s = dc_.afterFrame(frame, slam, out); !s.ok()) return s;
  const std::vector<RelationRecord> relations = dc_.takeRelationRecords();
  if (!relations.empty()) {
    if (!relations_log_.is_open() && !log_dir_.empty())
      if (Status s = openRelationsLog(); !s.ok()) return s;
    if (relations_log_.is_open()) {
      for (const RelationRecord& r : relations) writeRelationsCsvRow(relations_log_, r);
      relations_log_.flush();
      if (!relations_log_)
        return Status::Error("agent " + std::to_string(id()) + ": relations.csv: write failed");
    }
  }
  const std::vector<CoopEvent> events = dc_.takeEvents();
  if (!log_.is_open() || events.empty()) return Status::Ok();
  for (const CoopEvent& e : events) writeCoopCsvRow(log_, e);
  log_.flush();  // a process killed later still leaves its log
  return log_ ? Status::Ok()
              : Status::Error("agent " + std::to_string(id()) + ": coop.csv: write failed");
}

std::string DcLinkCore::report(double duration_s) const {
  const DcCooperationStatistics& s = dc_.statistics();
  char buf[1024];
  std::snprintf(
      buf, sizeof(buf),
      "UAV%d (%s CI) cooperation: peers %d, exchanges %lld (independent %lld), landmarks fused "
      "%lld (mapped %lld), requests sent %lld, shared sent %lld (archive offers %lld); not fused: "
      "no gain %lld, down-weighted %lld; "
      "rejected: invalid %lld, gate %lld, joint gate %lld, descriptor %lld, not in "
      "state %lld, stale %lld, duplicate %lld, reordered %lld, unknown peer %lld; peer "
      "restarts %lld, peer timeouts %lld, request timeouts %lld",
      id(), ciMethodName(dc_.options().ci_method).c_str(), s.peers_known, ll(s.exchanges_completed),
      ll(s.fused_independent), ll(s.landmarks_fused), ll(s.landmarks_mapped), ll(s.requests_sent),
      ll(s.shared_sent), ll(s.archive_offers), ll(s.skipped_no_gain), ll(s.peer_down_weighted),
      ll(s.rejected_invalid), ll(s.rejected_gate), ll(s.rejected_joint_gate),
      ll(s.rejected_descriptor), ll(s.shared_not_in_state), ll(s.rejected_stale),
      ll(s.rejected_duplicate), ll(s.rejected_reordered), ll(s.rejected_unknown_peer),
      ll(s.peer_restarts), ll(s.peer_timeouts), ll(s.request_timeouts));
  std::string line = buf;
  if (!dc_.options().frames_given || s.verifications > 0) {
    std::snprintf(buf, sizeof(buf),
                  "; frames: verifications %lld (failed %lld), relations adopted %lld, refined "
                  "%lld, rejected %lld, exchanges before a merge %lld",
                  ll(s.verifications), ll(s.verifications_failed), ll(s.relations_adopted),
                  ll(s.relations_refined), ll(s.relations_rejected), ll(s.skipped_unmerged));
    line += buf;
  }
  if (bytes_sent_.empty() || duration_s <= 0.0) return line;
  int64_t total = 0;
  std::string per_stream;
  for (const auto& [stream, n] : bytes_sent_) {
    total += n;
    per_stream += " " + stream + " " +
                  std::to_string(static_cast<int64_t>(static_cast<double>(n) / duration_s));
  }
  std::snprintf(buf, sizeof(buf), "; %.0f B/s (%s )", static_cast<double>(total) / duration_s,
                per_stream.c_str());
  return line + buf;
}

}  // namespace cvslam::coop
