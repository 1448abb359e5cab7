#pragma once
// The project's one random number generator, for everything that must be reproducible:
// the simulator's noise, the rendered worlds and textures, RANSAC sampling and vocabulary
// training. No global state: several simulations, agents and sensors coexist in one process,
// each with its own seeded stream.
//
// The generator is xoshiro256** seeded through splitmix64, and the normal variates come from
// Box–Muller, so that a stream is bit-identical on every platform and standard library
// (<random>'s distributions are implementation-defined). mixBits/hashCell are the same
// splitmix64 finaliser used as a stateless hash (per-cell randomness without a stream).

#include <cmath>
#include <cstdint>

namespace cvslam {

/// Stream tags of the simulator: one independent stream per agent and sensor (deriveSeed).
enum class RngStream : uint64_t {
  kWorld = 1,
  kImu = 2,
  kCamera = 3,
  kInitialState = 4,
  kGps = 5,
};

/// splitmix64 step: a good 64-bit mixer (Steele, Lea, Flood 2014).
inline uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// splitmix64 finaliser of `x` without a state: a well-mixed 64-bit hash.
inline uint64_t mixBits(uint64_t x) {
  return splitmix64(x);
}

/// Hash of an integer cell (i, j) and a salt.
inline uint64_t hashCell(int64_t i, int64_t j, uint64_t salt) {
  return mixBits(static_cast<uint64_t>(i) ^ mixBits(static_cast<uint64_t>(j) ^ mixBits(salt)));
}

/// Seed of the stream `stream` of agent `agent_id` in a scenario seeded with `seed`.
inline uint64_t deriveSeed(uint64_t seed, int64_t agent_id, RngStream stream) {
  uint64_t s = seed;
  uint64_t h = splitmix64(s);
  s = h ^ (static_cast<uint64_t>(agent_id) * 0xD1B54A32D192ED03ULL);
  h = splitmix64(s);
  s = h ^ (static_cast<uint64_t>(stream) * 0x8CB92BA72F3D8DD7ULL);
  return splitmix64(s);
}

/// xoshiro256** (Blackman & Vigna) with uniform and Gaussian variates.
class Rng {
 public:
  explicit Rng(uint64_t seed = 0) {
    uint64_t s = seed;
    for (uint64_t& w : s_) w = splitmix64(s);
  }

  uint64_t nextU64() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(nextU64() >> 11) * 0x1.0p-53; }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Standard normal N(0, 1) (Box–Muller, the second variate is kept for the next call).
  double gaussian() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }
  /// Uniform integer in [0, n), n > 0.
  uint64_t below(uint64_t n) { return nextU64() % n; }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4] = {0, 0, 0, 0};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace cvslam
