#pragma once
// Conversions between the core's cooperation messages (coop/coop_messages.h) and their
// lcmtypes (docs/architecture.md; thesis §6.6): CoopSummary ↔ agent_summary_t (the per-channel
// counters are left empty for the caller to fill), FeatureIndexList ↔ feature_index_t,
// SharedRequest ↔ shared_request_t and SharedLandmarks ↔ shared_landmarks2_t. The directed
// messages do not carry their addressee: it is the agent whose channel they travel on, so
// fromMessage() takes it. toMessage() finalizes the count fields; received messages must come
// through decodeMessage() (codec.h), which validates them, before fromMessage().
// Indices are uint32 in the core and travel as the same bit pattern in int32.

#include <type_traits>

#include "cvslam/coop/coop_messages.h"
#include "cvslam/coop/dc_link_core.h"
#include "cvslam/core/status.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {

Expected<cvslam::agent_summary_t> toMessage(const coop::CoopSummary& summary);
coop::CoopSummary fromMessage(const cvslam::agent_summary_t& msg);

Expected<cvslam::feature_index_t> toMessage(const coop::FeatureIndexList& list);
coop::FeatureIndexList fromMessage(const cvslam::feature_index_t& msg);

Expected<cvslam::shared_request_t> toMessage(const coop::SharedRequest& request);
coop::SharedRequest fromMessage(const cvslam::shared_request_t& msg, int to_agent);

/// The message has one descriptor length: if the landmarks' descriptors differ in length,
/// they are all left out.
Expected<cvslam::shared_landmarks2_t> toMessage(const coop::SharedLandmarks& shared);
coop::SharedLandmarks fromMessage(const cvslam::shared_landmarks2_t& msg, int to_agent);

/// Converts each message of an outbox to its lcmtype, in a fixed order (summary, index,
/// requests, shared landmarks), and calls `visit(channel, stream, to_agent, message)` with the
/// channel it travels on; to_agent is −1 for the broadcasts (summary, index). `visit` returns a
/// Status; the first error stops. The one place that maps an outbox to the wire, for
/// cvslam_agent (publishes) and cvslam_run --mode dc (delivers in-process).
template <typename Visit>
Status forEachOutboxMessage(const coop::CoopOutbox& box, int self, Visit&& visit) {
  auto one = [&](const auto& core, Stream stream, int to_agent) -> Status {
    auto m = toMessage(core);
    if (!m.ok()) return m.status();
    return visit(channelName(stream, to_agent < 0 ? self : to_agent), stream, to_agent, *m);
  };
  if (box.summary)
    if (Status s = one(*box.summary, Stream::kTeamSummary, -1); !s.ok()) return s;
  if (box.index)
    if (Status s = one(*box.index, Stream::kIndex, -1); !s.ok()) return s;
  for (const coop::SharedRequest& r : box.requests)
    if (Status s = one(r, Stream::kSharedReq, r.to_agent); !s.ok()) return s;
  for (const coop::SharedLandmarks& l : box.shared)
    if (Status s = one(l, Stream::kShared, l.to_agent); !s.ok()) return s;
  return Status::Ok();
}

/// A decoded cooperation message as the DC-link core takes it (coop/dc_link_core.h);
/// `receiver`: the agent it is delivered to (the addressee of the directed messages).
template <typename Msg>
coop::CoopMessage toCoopMessage(const Msg& msg, int receiver) {
  if constexpr (std::is_same_v<Msg, cvslam::agent_summary_t> ||
                std::is_same_v<Msg, cvslam::feature_index_t>) {
    return fromMessage(msg);
  } else {
    return fromMessage(msg, receiver);
  }
}

}  // namespace cvslam::transport
