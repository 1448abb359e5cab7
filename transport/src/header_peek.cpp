#include "cvslam/lcm/header_peek.h"

#include <utility>
#include <vector>

#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {
namespace {

template <typename Msg>
std::pair<int64_t, const char*> entry() {
  return {Msg::getHash(), Msg::getTypeName()};
}

// Every message type of lcmtypes/ (header_t itself is never sent alone).
const std::vector<std::pair<int64_t, const char*>>& knownTypes() {
  static const std::vector<std::pair<int64_t, const char*>> types = {
      entry<cvslam::agent_map_t>(),
      entry<cvslam::agent_state_t>(),
      entry<cvslam::agent_summary_t>(),
      entry<cvslam::feature_index_t>(),
      entry<cvslam::gs_state_t>(),
      entry<cvslam::imu_t>(),
      entry<cvslam::map_t>(),
      entry<cvslam::observation_batch_t>(),
      entry<cvslam::pose_t>(),
      entry<cvslam::shared_landmarks_t>(),  // superseded; in logs recorded before v2
      entry<cvslam::shared_landmarks2_t>(),
      entry<cvslam::shared_request_t>(),
      entry<cvslam::status_t>(),
      entry<cvslam::stereo_features_t>(),
      entry<cvslam::stereo_image_t>(),
  };
  return types;
}

uint64_t readBigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

std::optional<PeekedHeader> peekHeader(const void* data, std::size_t size) {
  constexpr std::size_t kHeaderEnd = 8 + 8 + 8 + 4;
  if (size < kHeaderEnd) return std::nullopt;
  const int64_t fingerprint = readFingerprint(data, size);
  const char* type = nullptr;
  for (const auto& [hash, name] : knownTypes()) {
    if (hash == fingerprint) type = name;
  }
  if (type == nullptr) return std::nullopt;
  const auto* p = static_cast<const uint8_t*>(data);
  PeekedHeader h;
  h.type = type;
  h.utime = static_cast<int64_t>(readBigEndian(p + 8, 8));
  h.seq = static_cast<int64_t>(readBigEndian(p + 16, 8));
  h.agent_id = static_cast<int32_t>(static_cast<uint32_t>(readBigEndian(p + 24, 4)));
  return h;
}

}  // namespace cvslam::transport
