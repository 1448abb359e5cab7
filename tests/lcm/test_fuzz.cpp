// Fault injection: ≥ 10 000 random or mutated buffers to every subscriber type, through
// the real receive path (memq://). Nothing may crash, throw or allocate without bound,
// and every buffer must be counted exactly once: as received if and only if it is a
// well-formed, valid message (decodeMessage is the oracle), otherwise as invalid. The
// mutation kinds that can never yield a valid message are asserted invalid outright.

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "cvslam/lcm/lcm_bus.h"
#include "lcm_test_util.h"
#include "message_mutator.h"
#include "sample_messages.h"

namespace cvslam::transport {
namespace {

using testing::alwaysInvalid;
using testing::kMutationKinds;
using testing::mutate;
using testing::Mutation;

constexpr int kBuffersPerTypeOnBus = 800;    // 13 types → 10 400 through the bus
constexpr int kBuffersPerTypeDirect = 4000;  // 13 types → 52 000 straight to the decoder

template <typename Msg>
std::string fuzzChannel() {
  return std::string("FUZZ/") + Msg::getTypeName();
}

struct Tally {
  int64_t valid = 0;
  int64_t invalid = 0;
};

template <typename Msg>
void fuzzThroughBus(LcmBus& bus, std::mt19937& rng) {
  Tally expected;
  for (int i = 0; i < kBuffersPerTypeOnBus; ++i) {
    const auto kind = static_cast<Mutation>(i % kMutationKinds);
    const std::vector<uint8_t> b = mutate<Msg>(kind, rng);
    const bool ok = decodeMessage<Msg>(b.data(), b.size()).ok();
    if (alwaysInvalid(kind)) {
      ASSERT_FALSE(ok) << Msg::getTypeName() << " mutation " << i % kMutationKinds;
    }
    ++(ok ? expected.valid : expected.invalid);
    ASSERT_TRUE(bus.publishRaw(fuzzChannel<Msg>(), b.data(), b.size()).ok());
    // Let the receive thread keep up, so LCM's own queue never overflows silently.
    if (i % 100 == 99) {
      ASSERT_TRUE(testing::waitFor([&] {
        const ChannelCounters c = bus.counters(fuzzChannel<Msg>());
        return c.received + c.dropped + c.invalid == i + 1;
      })) << Msg::getTypeName();
    }
  }
  const ChannelCounters c = bus.counters(fuzzChannel<Msg>());
  EXPECT_EQ(c.received, expected.valid) << Msg::getTypeName();
  EXPECT_EQ(c.invalid, expected.invalid) << Msg::getTypeName();
  EXPECT_EQ(c.dropped, 0) << Msg::getTypeName();
  EXPECT_GT(c.invalid, kBuffersPerTypeOnBus * 5 / 7) << Msg::getTypeName();
}

template <typename Msg>
void subscribeOne(LcmBus& bus) {
  EXPECT_TRUE(bus.subscribeQueue<Msg>(fuzzChannel<Msg>(), 100000).ok());
}

template <typename... Msgs>
struct FuzzAll {
  static void subscribe(LcmBus& bus) { (subscribeOne<Msgs>(bus), ...); }
  static void run(LcmBus& bus, std::mt19937& rng) { (fuzzThroughBus<Msgs>(bus, rng), ...); }
  static void direct(std::mt19937& rng) { (directDecode<Msgs>(rng), ...); }
  template <typename Msg>
  static void directDecode(std::mt19937& rng) {
    for (int i = 0; i < kBuffersPerTypeDirect; ++i) {
      const auto kind = static_cast<Mutation>(i % kMutationKinds);
      const std::vector<uint8_t> b = mutate<Msg>(kind, rng);
      Expected<Msg> m = decodeMessage<Msg>(b.data(), b.size());
      if (alwaysInvalid(kind)) {
        ASSERT_FALSE(m.ok()) << Msg::getTypeName();
      }
      if (!m.ok()) continue;
      // An accepted buffer is a message the publisher side would send as it is: it encodes
      // (encodeMessage validates again), to a buffer of the same size (the decoder read every
      // byte and nothing else), which decodes and encodes back to itself.
      Expected<std::vector<uint8_t>> again = encodeMessage(*m);
      ASSERT_TRUE(again.ok()) << Msg::getTypeName() << ": " << again.status().message();
      ASSERT_EQ(again->size(), b.size()) << Msg::getTypeName();
      Expected<Msg> m2 = decodeMessage<Msg>(again->data(), again->size());
      ASSERT_TRUE(m2.ok()) << Msg::getTypeName() << ": " << m2.status().message();
      Expected<std::vector<uint8_t>> third = encodeMessage(*m2);
      ASSERT_TRUE(third.ok()) << Msg::getTypeName();
      ASSERT_EQ(*third, *again) << Msg::getTypeName();
    }
  }
};

template <typename TypeList>
struct FuzzFor;
template <typename... Msgs>
struct FuzzFor<::testing::Types<Msgs...>> {
  using type = FuzzAll<Msgs...>;
};
using Fuzz = FuzzFor<testing::AllMessageTypes>::type;

TEST(LcmFuzz, EveryMutatedBufferIsCountedNeverCrashes) {
  BusOptions options;
  options.url = "memq://";
  Expected<std::unique_ptr<LcmBus>> bus = LcmBus::create(options);
  ASSERT_TRUE(bus.ok());
  Fuzz::subscribe(**bus);
  ASSERT_TRUE((*bus)->start().ok());
  std::mt19937 rng(20261121);
  Fuzz::run(**bus, rng);
  int64_t total = 0;
  for (const ChannelCounters& c : (*bus)->counters()) total += c.received + c.invalid;
  EXPECT_GE(total, 10000);
}

TEST(LcmFuzz, DecoderRejectsOrAcceptsOnlyValidMessages) {
  std::mt19937 rng(7);
  Fuzz::direct(rng);
}

}  // namespace
}  // namespace cvslam::transport
