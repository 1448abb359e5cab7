#pragma once
// Structural check of an encoded message body *before* the generated decode() runs.
//
// Why: lcm-gen's C++ decode() resizes each vector to the count read from the wire before
// checking that the bytes exist, so a corrupted count (say 2·10⁹) allocates and zeroes
// gigabytes, and a negative count or string length throws from std::vector/std::string.
// This walker follows the same layout as lcmtypes/*.lcm and checks every count and string
// length against the bytes that remain, so decode() only ever sees plausible counts.
// Tests assert that the walker consumes exactly getEncodedSize() − 8 bytes for every
// type, which catches a .lcm edit that was not mirrored here.

#include <cstddef>
#include <cstdint>

#include "cvslam/core/status.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {

/// `body` is the encoding after the 8-byte fingerprint. The pointer argument only selects
/// the message type (pass `static_cast<const Msg*>(nullptr)`). Fails on truncation,
/// impossible counts, and trailing bytes.
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::imu_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::stereo_image_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::stereo_features_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::pose_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::agent_map_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::agent_state_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::agent_summary_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::feature_index_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::shared_request_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::shared_landmarks2_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::observation_batch_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::gs_state_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::map_t*);
Status checkWireFormat(const uint8_t* body, std::size_t size, const cvslam::status_t*);

}  // namespace cvslam::transport
