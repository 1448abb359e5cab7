#pragma once
// Mutations of valid message encodings for the fuzz tests (tests/lcm/test_fuzz.cpp, the short
// one in CI) and the long fuzz program (tests/fuzz/fuzz_messages.cpp, scripts/fuzz_messages.sh).

#include <cstdint>
#include <random>
#include <vector>

#include "sample_messages.h"

namespace cvslam::transport::testing {

enum class Mutation { kRandom, kTruncate, kBitFlip, kFingerprint, kPoison, kCount, kExtend };
constexpr int kMutationKinds = 7;

bool alwaysInvalid(Mutation m) {
  return m != Mutation::kRandom && m != Mutation::kBitFlip;
}

template <typename Msg>
std::vector<uint8_t> mutate(Mutation kind, std::mt19937& rng) {
  static const std::vector<uint8_t> valid = encodedSample<Msg>();
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

}  // namespace cvslam::transport::testing
