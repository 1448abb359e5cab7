#include "cvslam/lcm/channels.h"

#include <array>
#include <cctype>
#include <limits>

namespace cvslam::transport {
namespace {

constexpr const char* kAgentPrefix = "UAV";

constexpr std::array<Stream, 14> kAllStreams = {
    Stream::kImu,         Stream::kStereo,  Stream::kFeatures,  Stream::kGroundTruth,
    Stream::kPose,        Stream::kIndex,   Stream::kSharedReq, Stream::kShared,
    Stream::kObs,         Stream::kGsState, Stream::kStatus,    Stream::kMap,
    Stream::kTeamSummary, Stream::kGsMap};

// Canonical decimal id: digits only, no leading zero (so every id has exactly one name).
std::optional<int32_t> parseId(const std::string& text) {
  if (text.empty() || text.size() > 10) return std::nullopt;
  if (text.size() > 1 && text[0] == '0') return std::nullopt;
  int64_t value = 0;
  for (char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
    value = value * 10 + (c - '0');
  }
  if (value > std::numeric_limits<int32_t>::max()) return std::nullopt;
  return static_cast<int32_t>(value);
}

}  // namespace

Stream channelStream(SensorEventType type) {
  switch (type) {
    case SensorEventType::kImu:
      return Stream::kImu;
    case SensorEventType::kGroundTruth:
      return Stream::kGroundTruth;
    case SensorEventType::kStereoImage:
      return Stream::kStereo;
    case SensorEventType::kFeatures:
      return Stream::kFeatures;
  }
  return Stream::kImu;  // unreachable: every enumerator is handled above
}

bool isPerAgent(Stream stream) {
  return stream != Stream::kTeamSummary && stream != Stream::kGsMap;
}

const char* streamName(Stream stream) {
  switch (stream) {
    case Stream::kImu:
      return "IMU";
    case Stream::kStereo:
      return "STEREO";
    case Stream::kFeatures:
      return "FEATURES";
    case Stream::kGroundTruth:
      return "GT";
    case Stream::kPose:
      return "POSE";
    case Stream::kIndex:
      return "INDEX";
    case Stream::kSharedReq:
      return "SHARED_REQ";
    case Stream::kShared:
      return "SHARED";
    case Stream::kObs:
      return "OBS";
    case Stream::kGsState:
      return "GS_STATE";
    case Stream::kStatus:
      return "STATUS";
    case Stream::kMap:
      return "MAP";
    case Stream::kTeamSummary:
      return "SUMMARY";
    case Stream::kGsMap:
      return "MAP";
  }
  return "";
}

std::string allAgentsPattern(Stream stream) {
  return std::string(kAgentPrefix) + "[0-9]+/" + streamName(stream);
}

bool isAgentPattern(const std::string& name) {
  for (Stream s : kAllStreams)
    if (isPerAgent(s) && name == allAgentsPattern(s)) return true;
  return false;
}

std::string channelName(Stream stream, int32_t agent_id) {
  switch (stream) {
    case Stream::kTeamSummary:
      return "TEAM/SUMMARY";
    case Stream::kGsMap:
      return "GS/MAP";
    default:
      break;
  }
  return kAgentPrefix + std::to_string(agent_id) + "/" + streamName(stream);
}

std::optional<ChannelId> parseChannel(const std::string& name) {
  const auto slash = name.find('/');
  if (slash == std::string::npos) return std::nullopt;
  const std::string head = name.substr(0, slash);
  const std::string tail = name.substr(slash + 1);
  for (Stream stream : kAllStreams) {
    if (tail != streamName(stream)) continue;
    if (!isPerAgent(stream)) {
      if (name == channelName(stream)) return ChannelId{std::nullopt, stream};
      continue;
    }
    // Not `UAV…`: maybe a broadcast with the same suffix (GS/MAP beside UAV<id>/MAP).
    if (head.rfind(kAgentPrefix, 0) != 0) continue;
    const auto id = parseId(head.substr(3));
    if (!id) return std::nullopt;
    return ChannelId{id, stream};
  }
  return std::nullopt;
}

bool isPlainChannelName(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/';
    if (!ok) return false;
  }
  return true;
}

}  // namespace cvslam::transport
