#pragma once
// The impairment of one emulated radio link, packet by packet (docs/transport.md "Multi-host
// runs"): what `tc netem loss L% delay D J rate R` does, for kernels without netem. Pure
// arithmetic on packet arrival times and sizes; cvslam_link_shaper applies its decisions to
// real packets held in an NFQUEUE.
//
//   LinkImpairment link(options);                        // options validated by the caller
//   const auto d = link.decide(now_s, bytes);            // per packet, in arrival order
//   if (!d.drop) release the packet at d.release_s;

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>

namespace cvslam::link {

struct LinkImpairmentOptions {
  double loss_percent = 0.0;  ///< each packet dropped independently with this probability
  double delay_ms = 0.0;      ///< mean one-way delay added
  /// Delay spread: uniform in [delay − jitter, delay + jitter] (netem's default
  /// distribution), never below 0.
  double jitter_ms = 0.0;
  /// With jitter, a later packet may overtake an earlier one (netem's behaviour). Off: a
  /// packet is never released before the one that arrived before it (a FIFO radio).
  bool reorder = true;
  /// Link rate [kbit/s]; 0 = unlimited. Packets are serialised one after the other at this
  /// rate before their delay (netem's `rate`), so a burst queues.
  double rate_kbit = 0.0;
  std::uint64_t seed = 1;  ///< of the loss and jitter draws: one seed, one loss pattern

  /// Empty if the options are usable; else one line saying which value is wrong.
  std::string validate() const;
};

struct LinkDecision {
  bool drop = false;
  double release_s = 0.0;  ///< when to let the packet through (same clock as `now_s`)
};

class LinkImpairment {
 public:
  explicit LinkImpairment(const LinkImpairmentOptions& options);

  /// Decides the fate of a packet of `bytes` bytes that arrived at `now_s`. Calls come in
  /// arrival order (non-decreasing `now_s`).
  LinkDecision decide(double now_s, std::size_t bytes);

 private:
  LinkImpairmentOptions o_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  double link_free_s_ = 0.0;     ///< when the serialiser (rate limit) is free again
  double last_release_s_ = 0.0;  ///< release of the previous packet (FIFO when !reorder)
};

}  // namespace cvslam::link
