// Centralised cooperation messages ↔ core structs (cc_convert.h): values survive the wire,
// batches that are absurd, reordered inside, or from no agent are refused after decoding; and a
// fuzz over observation_batch_t, gs_state_t and map_t: mutated buffers go through decode →
// convert → the ground station's orderer and joint filter without a crash, and only well-formed
// batches reach the filter (docs/ground_station.md).

#include "cvslam/lcm/cc_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cvslam/coop/cc_event_orderer.h"
#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/lcm/codec.h"
#include "lcm_test_util.h"

namespace cvslam::transport {
namespace {

using testing::throughWire;

/// `imu_samples` every 5 ms up to t_us (the fuzz gives each batch 2 s of them, so the filter
/// bridges the batches lost to corruption: it drops samples at or before its time).
coop::CcObservationBatch sampleBatch(int agent, int64_t t_us, int features = 5,
                                     int imu_samples = 20) {
  coop::CcObservationBatch b;
  b.agent_id = agent;
  b.t_us = t_us;
  b.frame.t_us = t_us;
  for (int i = 0; i < imu_samples; ++i) {
    ImuSample s;
    s.t_us = t_us - 5000 * (imu_samples - 1 - i);
    s.gyro_B = Eigen::Vector3d(0.01, -0.02, 0.003 * i);
    s.accel_B = Eigen::Vector3d(0.1, 0.0, -9.81);
    b.imu.push_back(s);
  }
  for (int i = 0; i < features; ++i) {
    StereoObservation o;
    o.index = 0xfffffff0u + static_cast<uint32_t>(i);  // uint32 bit pattern through int32
    o.landmark_id = i == 0 ? -1 : 1000 + i;
    o.type = i == 0 ? ObservationType::kNew : ObservationType::kReobserved;
    o.z = Eigen::Vector4d(100.0 + i, 120.0 - i, 90.0 + i, 120.0 - i);
    o.descriptor = std::vector<uint8_t>(32, static_cast<uint8_t>(i));
    b.frame.observations.push_back(o);
  }
  return b;
}

TEST(CcConvert, BatchRoundTrip) {
  const coop::CcObservationBatch b = sampleBatch(3, 1234567);
  auto m = toMessage(b);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->num_imu, 20);
  EXPECT_EQ(m->num_features, 5);
  EXPECT_EQ(m->descriptor_length, 32);
  auto back = fromMessage(throughWire(*m));
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->agent_id, 3);
  EXPECT_EQ(back->t_us, 1234567);
  ASSERT_EQ(back->imu.size(), b.imu.size());
  for (std::size_t i = 0; i < b.imu.size(); ++i) {
    EXPECT_EQ(back->imu[i].t_us, b.imu[i].t_us);
    // Single precision on the wire (observation_batch_t.lcm).
    EXPECT_EQ(back->imu[i].gyro_B, b.imu[i].gyro_B.cast<float>().cast<double>());
    EXPECT_EQ(back->imu[i].accel_B, b.imu[i].accel_B.cast<float>().cast<double>());
    EXPECT_NEAR(back->imu[i].accel_B.z(), b.imu[i].accel_B.z(), 1e-6);
  }
  ASSERT_EQ(back->frame.observations.size(), b.frame.observations.size());
  for (std::size_t i = 0; i < b.frame.observations.size(); ++i) {
    const StereoObservation& o = back->frame.observations[i];
    EXPECT_EQ(o.index, b.frame.observations[i].index);
    EXPECT_EQ(o.landmark_id, b.frame.observations[i].landmark_id);
    EXPECT_EQ(o.type, b.frame.observations[i].type);
    EXPECT_EQ(o.z, b.frame.observations[i].z.cast<float>().cast<double>());
    EXPECT_EQ(o.descriptor, b.frame.observations[i].descriptor);
  }
}

TEST(CcConvert, AbsurdOrInconsistentBatchesAreRefused) {
  auto refused = [](coop::CcObservationBatch b) {
    auto m = toMessage(b);
    if (!m.ok()) return true;
    auto bytes = encodeMessage(*m);
    if (!bytes.ok()) return true;
    auto decoded = decodeMessage<cvslam::observation_batch_t>(bytes->data(), bytes->size());
    return !decoded.ok() || !fromMessage(*decoded).ok();
  };
  EXPECT_FALSE(refused(sampleBatch(1, 1000000)));
  auto b = sampleBatch(1, 1000000);
  b.imu[3].t_us = b.imu[2].t_us;  // not ascending
  EXPECT_TRUE(refused(b));
  b = sampleBatch(1, 1000000);
  b.imu.back().t_us = 1000001;  // after the frame
  EXPECT_TRUE(refused(b));
  b = sampleBatch(1, 1000000);
  b.imu[0].gyro_B.x() = 1e6;  // absurd rate
  EXPECT_TRUE(refused(b));
  b = sampleBatch(1, 1000000);
  b.imu[0].accel_B.z() = std::nan("");
  EXPECT_TRUE(refused(b));
  b = sampleBatch(1, 1000000);
  b.frame.observations[1].z(0) = 1e9;  // absurd pixel
  EXPECT_TRUE(refused(b));
  b = sampleBatch(1, 1000000);
  // A distant landmark's noisy pair: the agent updates with it, so the ground station must too.
  b.frame.observations[1].z(2) = b.frame.observations[1].z(0) + 0.4;  // negative disparity
  EXPECT_FALSE(refused(b));
  b = sampleBatch(1, 1000000);
  b.frame.observations[2].landmark_id = -7;
  EXPECT_TRUE(refused(b));
  EXPECT_TRUE(refused(sampleBatch(0, 1000000)));   // the ground station's own id
  EXPECT_TRUE(refused(sampleBatch(-1, 1000000)));  // the replay's
  // A count that disagrees with its array never gets past the decoder.
  auto m = toMessage(sampleBatch(1, 1000000));
  ASSERT_TRUE(m.ok());
  m->num_features = 4;
  EXPECT_FALSE(validate(*m).ok());
}

TEST(CcConvert, EstimatesAndMapRoundTrip) {
  VehicleEstimate e;
  e.t_us = 42;
  e.x_v = Eigen::VectorXd::LinSpaced(15, -1.0, 1.0);
  e.P_v = Eigen::MatrixXd::Identity(15, 15) * 0.01;
  e.P_v(0, 1) = 0.002;  // row-major, not symmetric on purpose: the layout shows
  auto g = toMessage(e, "nhinf", 9);
  ASSERT_TRUE(g.ok());
  const cvslam::gs_state_t wire = throughWire(*g);
  EXPECT_EQ(wire.header.agent_id, 0);
  EXPECT_EQ(wire.map_version, 9);
  EXPECT_EQ(wire.covariance[1], 0.002);
  const VehicleEstimate back = fromMessage(wire);
  EXPECT_EQ(back.t_us, 42);
  EXPECT_EQ(back.x_v, e.x_v);
  EXPECT_EQ(back.P_v, e.P_v);
  const cvslam::agent_state_t pose = agentStateMessage(2, "ekf", 77, e.x_v, e.P_v);
  const VehicleEstimate own = estimateOf(throughWire(pose));
  EXPECT_EQ(own.t_us, 77);
  EXPECT_EQ(own.P_v, e.P_v);

  std::vector<MapLandmark> map(2);
  map[1].index = 0xffffffffu;
  map[1].p_LinN = Eigen::Vector3d(1, 2, -3);
  map[1].covariance << 1, 0.1, 0.2, 0.1, 2, 0.3, 0.2, 0.3, 3;
  auto mm = toMessage(map, 5, 3);
  ASSERT_TRUE(mm.ok());
  const cvslam::map_t mw = throughWire(*mm);
  ASSERT_EQ(mw.num_landmarks, 2);
  EXPECT_EQ(static_cast<uint32_t>(mw.index[1]), 0xffffffffu);
  EXPECT_EQ(mw.covariance[1], (std::vector<double>{1, 0.1, 0.2, 2, 0.3, 3}));
}

/// A random corruption of a valid encoding of `Msg`.
template <typename Msg>
std::vector<uint8_t> mutated(const Msg& valid_msg, std::mt19937& rng) {
  Msg msg = valid_msg;
  auto bytes = encodeMessage(msg);
  std::vector<uint8_t> b = *bytes;
  const int flips = 1 + static_cast<int>(rng() % 6);
  for (int i = 0; i < flips; ++i) {
    const std::size_t at = 8 + rng() % (b.size() - 8);  // keep the fingerprint: reach the body
    b[at] ^= static_cast<uint8_t>(1u << (rng() % 8));
  }
  if (rng() % 8 == 0) b.resize(8 + rng() % (b.size() - 8));
  return b;
}

TEST(CcFuzz, MutatedBatchesNeverReachTheFilterUnchecked) {
  coop::CcTeamFilterOptions options;
  options.association = coop::CcAssociation::kLocalIds;  // sampleBatch: an image agent's ids
  coop::CcTeamFilter filter(options);
  const int dim = options.slam.ins.estimate_imu_bias ? 15 : 9;
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(dim);
  x0(2) = -10.0;
  ASSERT_TRUE(
      filter.addVehicle(1, StereoCamera(), 0, x0, Eigen::MatrixXd::Identity(dim, dim) * 1e-4).ok());
  coop::CcEventOrderer orderer({1}, 1.0, 0.0);
  std::mt19937 rng(12);
  int decoded = 0, converted = 0, queued = 0, processed = 0;
  constexpr int kBuffers = 3000;
  for (int k = 0; k < kBuffers; ++k) {
    // Batches 100 ms apart, every other one corrupted.
    const coop::CcObservationBatch b = sampleBatch(1, 2000000 + 100000 * k, 8, 400);
    auto valid = toMessage(b);
    ASSERT_TRUE(valid.ok());
    const std::vector<uint8_t> bytes = k % 2 == 0 ? *encodeMessage(*valid) : mutated(*valid, rng);
    auto msg = decodeMessage<cvslam::observation_batch_t>(bytes.data(), bytes.size());
    if (!msg.ok()) continue;
    ++decoded;
    auto batch = fromMessage(*msg);
    if (!batch.ok()) continue;
    ++converted;
    ASSERT_TRUE(coop::validateBatch(*batch).ok());
    coop::CcEvent event;
    event.agent_id = batch->agent_id;
    event.t_us = batch->t_us;
    event.batch = std::move(*batch);
    if (orderer.push(std::move(event), 0.0) != coop::CcEventOrderer::Push::kQueued) continue;
    ++queued;
    coop::CcEvent next;
    while (orderer.pop(0.0, false, &next)) {
      coop::CcStepReport report;
      (void)filter.processBatch(next.batch, &report);
      processed += report.accepted ? 1 : 0;
    }
  }
  // Every path was exercised, and the filter's state stayed finite.
  EXPECT_GT(decoded, kBuffers / 10);
  EXPECT_LT(converted, decoded);
  EXPECT_GT(queued, 0);
  EXPECT_GT(processed, 0);
  auto e = filter.estimate(1);
  ASSERT_TRUE(e.ok());
  EXPECT_TRUE(e->x_v.allFinite());
  EXPECT_TRUE(e->P_v.allFinite());
  // The other two ground-station types: decode never crashes, a success is a valid message.
  cvslam::gs_state_t g = *toMessage(*e, "ekf", 1);
  cvslam::map_t m = *toMessage(filter.map(), 1, 1);
  for (int k = 0; k < 3000; ++k) {
    const auto gb = mutated(g, rng);
    auto gd = decodeMessage<cvslam::gs_state_t>(gb.data(), gb.size());
    if (gd.ok()) {
      EXPECT_TRUE(fromMessage(*gd).x_v.allFinite());
    }
    if (m.num_landmarks == 0) continue;
    const auto mb = mutated(m, rng);
    auto md = decodeMessage<cvslam::map_t>(mb.data(), mb.size());
    if (md.ok()) {
      EXPECT_TRUE(validate(*md).ok());
    }
  }
}

}  // namespace
}  // namespace cvslam::transport
