// Encoding/decoding of every cvslam message type: round trip, and clean failure on
// truncated, oversized, wrong-fingerprint, wrong-count and non-finite input.

#include <gtest/gtest.h>

#include <cmath>

#include "cvslam/lcm/codec.h"
#include "sample_messages.h"

namespace cvslam::transport {
namespace {

using testing::AllMessageTypes;
using testing::encodedSample;
using testing::sample;

template <typename Msg>
class CodecTest : public ::testing::Test {};
TYPED_TEST_SUITE(CodecTest, AllMessageTypes, testing::TypeNames);

TYPED_TEST(CodecTest, RoundTripReproducesTheMessage) {
  using Msg = TypeParam;
  const std::vector<uint8_t> encoded = encodedSample<Msg>();
  ASSERT_FALSE(encoded.empty());
  Expected<Msg> decoded = decodeMessage<Msg>(encoded.data(), encoded.size());
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  EXPECT_EQ(decoded->header.utime, sample<Msg>().header.utime);
  EXPECT_EQ(decoded->header.seq, 7);
  EXPECT_EQ(decoded->header.agent_id, 2);
  // Byte equality of the re-encoding compares every field, doubles bit for bit.
  Expected<std::vector<uint8_t>> again = encodeMessage(*decoded);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(*again, encoded);
}

TYPED_TEST(CodecTest, WireCheckConsumesExactlyTheGeneratedEncoding) {
  // Guards the hand-written layout in wire_check.cpp against .lcm edits.
  using Msg = TypeParam;
  const std::vector<uint8_t> encoded = encodedSample<Msg>();
  EXPECT_TRUE(
      checkWireFormat(encoded.data() + 8, encoded.size() - 8, static_cast<const Msg*>(nullptr))
          .ok());
  Msg empty{};
  ASSERT_TRUE(finalize(empty).ok());
  if (validate(empty).ok()) {
    const std::vector<uint8_t> b = testing::rawEncode(empty);
    EXPECT_TRUE(decodeMessage<Msg>(b.data(), b.size()).ok());
  }
}

TYPED_TEST(CodecTest, EveryTruncationFails) {
  using Msg = TypeParam;
  const std::vector<uint8_t> encoded = encodedSample<Msg>();
  for (std::size_t n = 0; n < encoded.size(); ++n) {
    Expected<Msg> decoded = decodeMessage<Msg>(encoded.data(), n);
    ASSERT_FALSE(decoded.ok()) << "prefix of " << n << " bytes decoded";
  }
}

TYPED_TEST(CodecTest, TrailingBytesAndSizeLimitFail) {
  using Msg = TypeParam;
  std::vector<uint8_t> encoded = encodedSample<Msg>();
  const std::size_t exact = encoded.size();
  EXPECT_FALSE(decodeMessage<Msg>(encoded.data(), exact, exact - 1).ok());
  EXPECT_TRUE(decodeMessage<Msg>(encoded.data(), exact, exact).ok());
  encoded.push_back(0);
  Expected<Msg> decoded = decodeMessage<Msg>(encoded.data(), encoded.size());
  ASSERT_FALSE(decoded.ok());
  EXPECT_NE(decoded.status().message().find("trailing"), std::string::npos);
}

TYPED_TEST(CodecTest, WrongFingerprintFails) {
  using Msg = TypeParam;
  std::vector<uint8_t> encoded = encodedSample<Msg>();
  encoded[3] ^= 0x40;
  Expected<Msg> decoded = decodeMessage<Msg>(encoded.data(), encoded.size());
  ASSERT_FALSE(decoded.ok());
  EXPECT_NE(decoded.status().message().find("fingerprint"), std::string::npos);
  // Another type's valid encoding is rejected by its fingerprint, too.
  const std::vector<uint8_t> other = std::is_same<Msg, cvslam::imu_t>::value
                                         ? encodedSample<cvslam::pose_t>()
                                         : encodedSample<cvslam::imu_t>();
  EXPECT_FALSE(decodeMessage<Msg>(other.data(), other.size()).ok());
}

TYPED_TEST(CodecTest, CorruptCountFieldsFailWithoutHugeAllocation) {
  using Msg = TypeParam;
  const testing::CountField field = testing::firstCount(static_cast<const Msg*>(nullptr));
  if (field.offset < 0) {
    // A type without a count field (imu_t, pose_t) has one encoded size whatever its content:
    // there is no count to corrupt (EveryTruncationFails and TrailingBytesAndSizeLimitFail
    // cover its length). A variable-size field added to it needs a firstCount entry.
    Msg empty{};
    ASSERT_TRUE(finalize(empty).ok());
    EXPECT_EQ(testing::rawEncode(empty).size(), encodedSample<Msg>().size())
        << Msg::getTypeName() << " has a variable size but no count field in firstCount";
    return;
  }
  const std::vector<uint8_t> encoded = encodedSample<Msg>();
  ASSERT_EQ(testing::readInt32(encoded, field.offset), field.value) << "offset table stale";
  for (int32_t bad :
       {field.value + 1, field.value - 1, -1, 0x7fffffff, -0x7fffffff - 1, 0x10000000}) {
    std::vector<uint8_t> corrupt = encoded;
    testing::writeInt32(corrupt, field.offset, bad);
    EXPECT_FALSE(decodeMessage<Msg>(corrupt.data(), corrupt.size()).ok()) << "count " << bad;
  }
}

TYPED_TEST(CodecTest, NonFiniteOrOutOfRangeContentFailsBothWays) {
  using Msg = TypeParam;
  Msg m = sample<Msg>();
  testing::poison(m);
  EXPECT_FALSE(validate(m).ok());
  EXPECT_FALSE(encodeMessage(m).ok()) << "publisher side must refuse it";
  const std::vector<uint8_t> b = testing::rawEncode(m);
  EXPECT_FALSE(decodeMessage<Msg>(b.data(), b.size()).ok()) << "receiver side must reject it";
}

TEST(Finalize, SetsCountsFromVectors) {
  cvslam::stereo_features_t m{};
  m.index = {1, 2};
  m.u_left = m.v_left = m.u_right = m.v_right = {1.0, 2.0};
  m.descriptors = {{1, 2, 3}, {4, 5, 6}};
  ASSERT_TRUE(finalize(m).ok());
  EXPECT_EQ(m.num_features, 2);
  EXPECT_EQ(m.descriptor_length, 3);
  cvslam::agent_summary_t s{};
  s.channel = {"A", "B", "C"};
  s.received = s.dropped = s.invalid = {1, 2, 3};
  ASSERT_TRUE(finalize(s).ok());
  EXPECT_EQ(s.num_channels, 3);
}

TEST(Finalize, RejectsInconsistentParallelArrays) {
  cvslam::stereo_features_t m = sample<cvslam::stereo_features_t>();
  m.v_right.pop_back();
  EXPECT_FALSE(finalize(m).ok());
  m = sample<cvslam::stereo_features_t>();
  m.descriptors[1].push_back(0);
  EXPECT_FALSE(finalize(m).ok());
  cvslam::map_t map = sample<cvslam::map_t>();
  map.position[0].resize(2);
  EXPECT_FALSE(finalize(map).ok());
  cvslam::observation_batch_t batch = sample<cvslam::observation_batch_t>();
  batch.type.push_back(0);
  EXPECT_FALSE(finalize(batch).ok());
}

TEST(Validate, ChecksSemanticSizes) {
  cvslam::agent_state_t s = sample<cvslam::agent_state_t>();
  s.covariance.resize(80);
  ASSERT_TRUE(finalize(s).ok());
  EXPECT_FALSE(validate(s).ok()) << "covariance must be state_dim²";
  s = sample<cvslam::agent_state_t>();
  s.state.resize(10);
  s.covariance.resize(100);
  ASSERT_TRUE(finalize(s).ok());
  EXPECT_FALSE(validate(s).ok()) << "state_dim must be 9 or 15";

  cvslam::stereo_image_t img = sample<cvslam::stereo_image_t>();
  img.right_data.pop_back();
  ASSERT_TRUE(finalize(img).ok());
  EXPECT_FALSE(validate(img).ok()) << "mono8 size must be stride·height";
  img = sample<cvslam::stereo_image_t>();
  img.encoding = cvslam::stereo_image_t::ENCODING_PNG;
  img.stride = 0;
  EXPECT_FALSE(validate(img).ok()) << "PNG bytes need the PNG signature";
  const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0};
  img.left_data = img.right_data = png;
  ASSERT_TRUE(finalize(img).ok());
  EXPECT_TRUE(validate(img).ok()) << validate(img).message();
}

}  // namespace
}  // namespace cvslam::transport
