#pragma once
// The one place LCM channel names are built and parsed (docs/architecture.md): per-agent streams
// `UAV<id>/<STREAM>` and the broadcasts `TEAM/SUMMARY`, `GS/MAP`. LCM treats a
// subscription name as a regex, so names are restricted to [A-Za-z0-9_/] and can be
// subscribed to verbatim.

#include <cstdint>
#include <optional>
#include <string>

#include "cvslam/core/sensor_event_type.h"

namespace cvslam::transport {

/// Every kind of channel. Per-agent streams first, then the broadcasts.
enum class Stream {
  kImu,          ///< UAV<id>/IMU         imu_t
  kStereo,       ///< UAV<id>/STEREO      stereo_image_t
  kFeatures,     ///< UAV<id>/FEATURES    stereo_features_t
  kGroundTruth,  ///< UAV<id>/GT          pose_t
  kPose,         ///< UAV<id>/POSE        agent_state_t
  kIndex,        ///< UAV<id>/INDEX       feature_index_t
  kSharedReq,    ///< UAV<id>/SHARED_REQ  shared_request_t (directed to id)
  kShared,       ///< UAV<id>/SHARED      shared_landmarks2_t (directed to id)
  kObs,          ///< UAV<id>/OBS         observation_batch_t
  kGsState,      ///< UAV<id>/GS_STATE    gs_state_t (directed to id)
  kStatus,       ///< UAV<id>/STATUS      status_t
  kMap,          ///< UAV<id>/MAP         agent_map_t (the agent's landmarks, for displays)
  kTeamSummary,  ///< TEAM/SUMMARY        agent_summary_t (broadcast)
  kGsMap,        ///< GS/MAP              map_t (broadcast)
};

/// The per-agent stream that carries a kind of sensor data (UAV<id>/IMU, /GT, /STEREO,
/// /FEATURES).
Stream channelStream(SensorEventType type);

/// A channel name taken apart. agent_id is empty for the broadcasts.
struct ChannelId {
  std::optional<int32_t> agent_id;
  Stream stream = Stream::kImu;
};

/// True for the streams that carry an agent id in their name.
bool isPerAgent(Stream stream);

/// The stream's suffix as it appears in the name: "IMU", "SHARED_REQ", "SUMMARY", ...
const char* streamName(Stream stream);

/// Builds the name of a channel. For a per-agent stream agent_id must be ≥ 0 (the ground
/// station is 0, docs/architecture.md); for a broadcast it is ignored.
std::string channelName(Stream stream, int32_t agent_id = 0);

/// Parses a channel name built by channelName(); empty for anything else (including
/// non-canonical ids such as "UAV01" or "UAV+1").
std::optional<ChannelId> parseChannel(const std::string& name);

/// True if `name` is non-empty and uses only [A-Za-z0-9_/], i.e. contains no regex
/// metacharacter and so matches only itself when subscribed to.
bool isPlainChannelName(const std::string& name);

/// The LCM subscription pattern matching a per-agent stream of every agent, e.g.
/// "UAV[0-9]+/INDEX" (the only regular expressions LcmBus accepts, see isAgentPattern).
std::string allAgentsPattern(Stream stream);

/// True if `name` is allAgentsPattern() of some per-agent stream.
bool isAgentPattern(const std::string& name);

/// Shorthands, one per stream, so call sites read `channels::imu(2)`.
/// The ground station's agent id in headers and per-agent channel names (UAVs count from 1).
constexpr int32_t kGroundStationId = 0;

namespace channels {
inline std::string imu(int32_t id) {
  return channelName(Stream::kImu, id);
}
inline std::string stereo(int32_t id) {
  return channelName(Stream::kStereo, id);
}
inline std::string features(int32_t id) {
  return channelName(Stream::kFeatures, id);
}
inline std::string groundTruth(int32_t id) {
  return channelName(Stream::kGroundTruth, id);
}
inline std::string pose(int32_t id) {
  return channelName(Stream::kPose, id);
}
inline std::string index(int32_t id) {
  return channelName(Stream::kIndex, id);
}
inline std::string sharedRequest(int32_t id) {
  return channelName(Stream::kSharedReq, id);
}
inline std::string shared(int32_t id) {
  return channelName(Stream::kShared, id);
}
inline std::string observations(int32_t id) {
  return channelName(Stream::kObs, id);
}
inline std::string gsState(int32_t id) {
  return channelName(Stream::kGsState, id);
}
inline std::string status(int32_t id) {
  return channelName(Stream::kStatus, id);
}
inline std::string agentMap(int32_t id) {
  return channelName(Stream::kMap, id);
}
inline std::string teamSummary() {
  return channelName(Stream::kTeamSummary);
}
inline std::string gsMap() {
  return channelName(Stream::kGsMap);
}
}  // namespace channels

}  // namespace cvslam::transport
