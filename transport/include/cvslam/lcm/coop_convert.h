#pragma once
// Conversions between the core's cooperation messages (coop/coop_messages.h) and their
// lcmtypes (DESIGN.md §4; thesis §6.6): CoopSummary ↔ agent_summary_t (the per-channel
// counters are left empty for the caller to fill), FeatureIndexList ↔ feature_index_t,
// SharedRequest ↔ shared_request_t and SharedLandmarks ↔ shared_landmarks_t. The directed
// messages do not carry their addressee: it is the agent whose channel they travel on, so
// fromMessage() takes it. toMessage() finalizes the count fields; received messages must come
// through decodeMessage() (codec.h), which validates them, before fromMessage().
// Indices are uint32 in the core and travel as the same bit pattern in int32.

#include "cvslam/coop/coop_messages.h"
#include "cvslam/core/status.h"
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
Expected<cvslam::shared_landmarks_t> toMessage(const coop::SharedLandmarks& shared);
coop::SharedLandmarks fromMessage(const cvslam::shared_landmarks_t& msg, int to_agent);

}  // namespace cvslam::transport
