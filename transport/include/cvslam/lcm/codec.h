#pragma once
// Safe encoding and decoding of cvslam messages: the only path between bytes and typed
// messages. Decoding never throws, never allocates more than the buffer justifies, and
// accepts a buffer only if it is exactly one well-formed, valid message of type Msg.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/lcm/message_finalize.h"
#include "cvslam/lcm/message_validate.h"
#include "cvslam/lcm/wire_check.h"

namespace cvslam::transport {

/// Largest message accepted by default [bytes]: two 752×480 mono8 images are 0.7 MB;
/// 64 MB leaves room for big maps while bounding what a corrupt packet can cost.
constexpr std::size_t kDefaultMaxMessageBytes = std::size_t{64} << 20;

/// The 8-byte big-endian fingerprint at the start of an encoding, or 0 if too short.
int64_t readFingerprint(const void* data, std::size_t size);

/// Decodes `data` as a Msg: size limit, fingerprint, wire structure, generated decode(),
/// exact length, then validate(). The error message names the first failing check.
template <typename Msg>
Expected<Msg> decodeMessage(const void* data, std::size_t size,
                            std::size_t max_bytes = kDefaultMaxMessageBytes) {
  constexpr std::size_t kFingerprint = 8;
  if (size > max_bytes || size > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    return Status::Error("oversized: " + std::to_string(size) + " bytes > limit " +
                         std::to_string(max_bytes));
  }
  if (size < kFingerprint) return Status::Error("truncated: no fingerprint");
  if (readFingerprint(data, size) != Msg::getHash()) {
    return Status::Error(std::string("wrong fingerprint for ") + Msg::getTypeName());
  }
  const auto* bytes = static_cast<const uint8_t*>(data);
  Status wire =
      checkWireFormat(bytes + kFingerprint, size - kFingerprint, static_cast<const Msg*>(nullptr));
  if (!wire.ok()) return wire;
  Msg msg;
  const int used = msg.decode(data, 0, static_cast<int>(size));
  if (used < 0 || static_cast<std::size_t>(used) != size) {
    return Status::Error(std::string("decode failed for ") + Msg::getTypeName());
  }
  Status valid = validate(msg);
  if (!valid.ok()) return valid;
  return msg;
}

/// finalize()s `msg` (count fields), validate()s it and encodes it. `msg` keeps the counts.
template <typename Msg>
Expected<std::vector<uint8_t>> encodeMessage(Msg& msg) {
  Status status = finalize(msg);
  if (status.ok()) status = validate(msg);
  if (!status.ok()) {
    return Status::Error(std::string("cannot encode ") + Msg::getTypeName() + ": " +
                         status.message());
  }
  std::vector<uint8_t> buffer(static_cast<std::size_t>(msg.getEncodedSize()));
  const int written = msg.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
  if (written < 0 || static_cast<std::size_t>(written) != buffer.size()) {
    return Status::Error(std::string("encode failed for ") + Msg::getTypeName());
  }
  return buffer;
}

}  // namespace cvslam::transport
