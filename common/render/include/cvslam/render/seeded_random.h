#pragma once
// Small deterministic random numbers for procedural content (textures, worlds).
//
// Why not <random> distributions: their output is implementation-defined, and the worlds
// must be identical on every platform for the same seed. SplitMix64 is tiny, fast and
// fully specified; `hash` gives stateless per-cell randomness (texture tile choice).

#include <cstdint>

namespace cvslam {

/// SplitMix64 finaliser: a well-mixed 64-bit hash of `x`.
inline uint64_t mixBits(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Hash of an integer cell (i, j) and a salt.
inline uint64_t hashCell(int64_t i, int64_t j, uint64_t salt) {
  return mixBits(static_cast<uint64_t>(i) ^ mixBits(static_cast<uint64_t>(j) ^ mixBits(salt)));
}

class SeededRandom {
 public:
  explicit SeededRandom(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return mixBits(state_);
  }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n).
  int index(int n) { return static_cast<int>(next() % static_cast<uint64_t>(n)); }

 private:
  uint64_t state_;
};

}  // namespace cvslam
