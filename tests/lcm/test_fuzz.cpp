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
#include "sample_messages.h"

namespace cvslam::transport {
namespace {

using testing::encodedSample;
using testing::sample;

constexpr int kBuffersPerTypeOnBus = 800;    // 13 types → 10 400 through the bus
constexpr int kBuffersPerTypeDirect = 4000;  // 13 types → 52 000 straight to the decoder

enum class Mutation { kRandom, kTruncate, kBitFlip, kFingerprint, kPoison, kCount, kExtend };
constexpr int kMutationKinds = 7;

bool alwaysInvalid(Mutation m) {
  return m != Mutation::kRandom && m != Mutation::kBitFlip;
}

template <typename Msg>
std::vector<uint8_t> mutate(Mutation kind, std::mt19937& rng) {
  const std::vector<uint8_t> valid = encodedSample<Msg>();
  auto uniform = [&rng](std::size_t lo, std::size_t hi) {
    return std::uniform_int_distribution<std::size_t>(lo, hi)(rng);
  };
  auto randomByte = [&rng] { return static_cast<uint8_t>(rng() & 0xff); };
  std::vector<uint8_t> b = valid;
  switch (kind) {
    case Mutation::kRandom: {
      b.resize(uniform(0, 2 * valid.size()));
      for (auto& x : b) x = randomByte();
      // Half keep the right fingerprint, so the body parser sees random counts.
      if (b.size() >= 8 && (rng() & 1)) std::copy(valid.begin(), valid.begin() + 8, b.begin());
      break;
    }
    case Mutation::kTruncate:
      b.resize(uniform(0, valid.size() - 1));
      break;
    case Mutation::kBitFlip: {
      const std::size_t flips = uniform(1, 8);
      for (std::size_t i = 0; i < flips; ++i) {
        b[uniform(0, b.size() - 1)] ^= static_cast<uint8_t>(1u << uniform(0, 7));
      }
      break;
    }
    case Mutation::kFingerprint:
      b[uniform(0, 7)] ^= static_cast<uint8_t>(1u << uniform(0, 7));
      break;
    case Mutation::kPoison: {
      Msg m = sample<Msg>();
      testing::poison(m);
      b = testing::rawEncode(m);
      break;
    }
    case Mutation::kCount: {
      const testing::CountField field = testing::firstCount(static_cast<const Msg*>(nullptr));
      if (field.offset < 0) {  // fixed-size type: change the length instead
        b.push_back(randomByte());
        break;
      }
      int32_t bad = static_cast<int32_t>(rng());
      if (rng() & 1) bad = field.value + static_cast<int32_t>(uniform(1, 3)) * (rng() & 1 ? 1 : -1);
      if (bad == field.value) bad = field.value + 1;
      testing::writeInt32(b, field.offset, bad);
      break;
    }
    case Mutation::kExtend: {
      const std::size_t extra = uniform(1, 64);
      for (std::size_t i = 0; i < extra; ++i) b.push_back(randomByte());
      break;
    }
  }
  return b;
}

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
      if (m.ok()) {
        ASSERT_TRUE(validate(*m).ok());
      }
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
