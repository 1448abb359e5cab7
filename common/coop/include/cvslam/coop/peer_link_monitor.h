#pragma once
// Link quality per peer as the cooperation messages arrive (docs/transport.md, lossy links):
// per peer and stream (summary, index, request, landmarks) the messages received and the ones
// missing by header.seq, and the data time of the newest message, whose age against the
// agent's own time tells how stale the peer's news is. A sender that restarts (seq going back)
// starts a new count. No transport: fed the cooperation messages' headers.

#include <array>
#include <cstdint>
#include <map>
#include <string>

#include "cvslam/coop/coop_messages.h"
#include "cvslam/coop/dc_link_core.h"

namespace cvslam::coop {

class PeerLinkMonitor {
 public:
  enum Stream { kSummary = 0, kIndex = 1, kRequest = 2, kLandmarks = 3, kStreams = 4 };
  struct Link {
    int64_t received = 0;      ///< messages that arrived
    int64_t missing = 0;       ///< seq numbers skipped (lost on the way, or dropped on arrival)
    int64_t newest_t_us = -1;  ///< data time of the newest message
    int64_t expected() const { return received + missing; }
  };

  void add(const CoopHeader& header, Stream stream);
  /// A received cooperation message (its stream is its alternative of CoopMessage).
  void add(const CoopMessage& message);
  /// Per peer, summed over its streams.
  std::map<int, Link> links() const;
  /// "2: 118/120 age 0.10 s; 3: …" with ages against `now_us` (the agent's data time).
  std::string text(int64_t now_us) const;

 private:
  struct PerStream {
    int64_t last_seq = -1;
    Link link;
  };
  std::map<int, std::array<PerStream, kStreams>> peers_;
};

}  // namespace cvslam::coop
