#include "cvslam/coop/peer_link_monitor.h"

#include <algorithm>
#include <cstdio>
#include <type_traits>
#include <variant>

namespace cvslam::coop {

void PeerLinkMonitor::add(const CoopHeader& header, Stream stream) {
  // A sender restarting begins again at 0 (or far below): a new count, not a late message.
  constexpr int64_t kRestartJump = 1000;
  PerStream& s = peers_[header.agent_id][stream];
  if (s.last_seq < 0 || header.seq > s.last_seq) {
    if (s.last_seq >= 0) s.link.missing += header.seq - s.last_seq - 1;
    s.last_seq = header.seq;
  } else if (header.seq == 0 || s.last_seq - header.seq > kRestartJump) {
    s.last_seq = header.seq;
  } else if (header.seq < s.last_seq && s.link.missing > 0) {
    --s.link.missing;  // reordered: it was counted missing when a later one came first
  }
  ++s.link.received;
  s.link.newest_t_us = std::max(s.link.newest_t_us, header.t_us);
}

void PeerLinkMonitor::add(const CoopMessage& message) {
  static_assert(
      std::is_same_v<std::variant_alternative_t<kSummary, CoopMessage>, CoopSummary> &&
          std::is_same_v<std::variant_alternative_t<kIndex, CoopMessage>, FeatureIndexList> &&
          std::is_same_v<std::variant_alternative_t<kRequest, CoopMessage>, SharedRequest> &&
          std::is_same_v<std::variant_alternative_t<kLandmarks, CoopMessage>, SharedLandmarks>,
      "Stream follows the order of CoopMessage's alternatives");
  std::visit([&](const auto& m) { add(m.header, static_cast<Stream>(message.index())); }, message);
}

std::map<int, PeerLinkMonitor::Link> PeerLinkMonitor::links() const {
  std::map<int, Link> out;
  for (const auto& [peer, streams] : peers_) {
    Link& l = out[peer];
    for (const PerStream& s : streams) {
      l.received += s.link.received;
      l.missing += s.link.missing;
      l.newest_t_us = std::max(l.newest_t_us, s.link.newest_t_us);
    }
  }
  return out;
}

std::string PeerLinkMonitor::text(int64_t now_us) const {
  std::string out;
  for (const auto& [peer, l] : links()) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s%d: %lld/%lld age %.2f s", out.empty() ? "" : ", ", peer,
                  static_cast<long long>(l.received), static_cast<long long>(l.expected()),
                  l.newest_t_us < 0 ? 0.0 : static_cast<double>(now_us - l.newest_t_us) * 1e-6);
    out += buf;
  }
  return out.empty() ? "none" : out;
}

}  // namespace cvslam::coop
