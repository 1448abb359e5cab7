#pragma once
// Reads the header of an encoded cvslam message without decoding the rest.
//
// LCM encodes a message as its 8-byte fingerprint followed by the fields in order; nested
// structs are encoded inline without their own fingerprint. Every cvslam message begins
// with `header_t header` (docs/architecture.md), so bytes 8..15 are header.utime, 16..23
// header.seq and 24..27 header.agent_id, all big-endian. The fingerprint tells whether the
// buffer is one of our types at all; foreign messages yield no header.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace cvslam::transport {

struct PeekedHeader {
  std::string type;  ///< e.g. "imu_t"
  int64_t utime = 0;
  int64_t seq = 0;
  int32_t agent_id = 0;
};

/// The header if `data` starts with the fingerprint of a cvslam type and is long enough.
std::optional<PeekedHeader> peekHeader(const void* data, std::size_t size);

}  // namespace cvslam::transport
