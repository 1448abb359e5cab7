#include "cvslam/lcm/codec.h"

namespace cvslam::transport {

int64_t readFingerprint(const void* data, std::size_t size) {
  if (size < 8) return 0;
  const auto* bytes = static_cast<const uint8_t*>(data);
  uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value = (value << 8) | bytes[i];
  return static_cast<int64_t>(value);
}

}  // namespace cvslam::transport
