#include "cvslam/lcm/wire_check.h"

#include <string>

namespace cvslam::transport {
namespace {

// Sizes on the wire (LCM encodes big-endian, no padding).
constexpr std::size_t kI8 = 1, kI32 = 4, kI64 = 8, kF32 = 4, kF64 = 8;
constexpr std::size_t kHeader = kI64 + kI64 + kI32;  // header_t: utime, seq, agent_id

// Reads counts and skips payload; any failure sticks and later calls become no-ops.
class WireReader {
 public:
  WireReader(const uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  WireReader& skip(std::size_t bytes) {
    if (ok() && bytes > size_ - pos_) fail("truncated");
    if (ok()) pos_ += bytes;
    return *this;
  }
  /// Reads a count (int32) that must be ≥ 0.
  WireReader& count(int32_t& out) {
    out = 0;
    if (ok() && kI32 > size_ - pos_) fail("truncated");
    if (!ok()) return *this;
    const uint32_t raw = (uint32_t{data_[pos_]} << 24) | (uint32_t{data_[pos_ + 1]} << 16) |
                         (uint32_t{data_[pos_ + 2]} << 8) | uint32_t{data_[pos_ + 3]};
    pos_ += kI32;
    out = static_cast<int32_t>(raw);
    if (out < 0) fail("negative count " + std::to_string(out));
    return *this;
  }
  /// `n` elements of `element_bytes` each; the product cannot overflow (n < 2^31).
  WireReader& array(int32_t n, std::size_t element_bytes) {
    return skip(static_cast<std::size_t>(n) * element_bytes);
  }
  /// An LCM string: int32 length including the terminating NUL, then the bytes.
  WireReader& string() {
    int32_t length = 0;
    count(length);
    if (ok() && length < 1) fail("string length below 1");
    if (ok() && length > 0) skip(static_cast<std::size_t>(length));
    if (ok() && data_[pos_ - 1] != 0) fail("string not NUL-terminated");
    return *this;
  }
  WireReader& strings(int32_t n) {
    for (int32_t i = 0; i < n && ok(); ++i) string();
    return *this;
  }
  WireReader& header() { return skip(kHeader); }

  Status finish() {
    if (ok() && pos_ != size_) fail(std::to_string(size_ - pos_) + " trailing bytes");
    return ok() ? Status::Ok() : Status::Error("malformed encoding: " + error_);
  }

 private:
  bool ok() const { return error_.empty(); }
  void fail(std::string message) {
    if (ok()) error_ = std::move(message);
  }
  const uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string error_;
};

}  // namespace

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::imu_t*) {
  return WireReader(body, size).header().skip(6 * kF64).finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::stereo_image_t*) {
  WireReader r(body, size);
  int32_t left = 0, right = 0;
  r.header().skip(kI8 + 3 * kI32);  // encoding, width, height, stride
  r.count(left).array(left, kI8);
  r.count(right).array(right, kI8);
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::stereo_features_t*) {
  WireReader r(body, size);
  int32_t n = 0, descriptor_length = 0;
  r.header().count(n).array(n, kI32 + 4 * kF64);  // index, u_left, v_left, u_right, v_right
  r.count(descriptor_length).array(n, static_cast<std::size_t>(descriptor_length));
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::pose_t*) {
  return WireReader(body, size).header().skip(13 * kF64).finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::agent_state_t*) {
  WireReader r(body, size);
  int32_t dim = 0, cov = 0;
  r.header().string();
  r.count(dim).array(dim, kF64);
  r.count(cov).array(cov, kF64);
  r.skip(2 * kI32);  // num_landmarks, num_archived
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::agent_map_t*) {
  WireReader r(body, size);
  int32_t n = 0;
  r.header().count(n).array(n, kI64 + 4 * kF32 + kI8);  // id, position, position_std, active
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::agent_summary_t*) {
  WireReader r(body, size);
  int32_t n = 0;
  r.header().string().skip(kI64 + 6 * kF64 + kI32 + kF64 + kI8);  // boot_id .. own_frame
  r.count(n).strings(n).array(n, 3 * kI64);                       // received, dropped, invalid
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::feature_index_t*) {
  WireReader r(body, size);
  int32_t n = 0;
  r.header().skip(kI8).count(n).array(n, kI32);
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::shared_request_t*) {
  WireReader r(body, size);
  int32_t n = 0;
  r.header().count(n).array(n, kI32);
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::shared_landmarks2_t*) {
  WireReader r(body, size);
  int32_t sources = 0, n = 0, descriptor_length = 0;
  r.header().skip(kF64).count(sources).array(sources, kI32);
  r.count(n).array(n, kI32 + 3 * kF64 + 6 * kF64);
  int32_t cross = 0;
  r.count(cross).array(cross, 9 * kF64);
  r.count(descriptor_length).array(n, static_cast<std::size_t>(descriptor_length));
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::observation_batch_t*) {
  WireReader r(body, size);
  int32_t num_imu = 0, n = 0, descriptor_length = 0;
  r.header().count(num_imu).array(num_imu, kI32 + 6 * kF32);  // age, gyro, accel
  r.count(n).array(n, kI32 + kI8 + kI64 + 4 * kF32);          // index type landmark_id u v u v
  r.count(descriptor_length).array(n, static_cast<std::size_t>(descriptor_length));
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::gs_state_t*) {
  WireReader r(body, size);
  int32_t dim = 0, cov = 0;
  r.header().string().skip(kI64);
  r.count(dim).array(dim, kF64);
  r.count(cov).array(cov, kF64);
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::map_t*) {
  WireReader r(body, size);
  int32_t n = 0;
  r.header().skip(kI64).count(n).array(n, kI32 + 9 * kF64);
  return r.finish();
}

Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::status_t*) {
  return WireReader(body, size).header().skip(kI64 + kI8).string().finish();
}

}  // namespace cvslam::transport
