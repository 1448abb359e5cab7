#include "link_impairment.h"

#include <algorithm>
#include <cmath>

namespace cvslam::link {

namespace {
constexpr double kMsPerS = 1000.0;
constexpr double kBitsPerByte = 8.0;
constexpr double kBitsPerKbit = 1000.0;
constexpr double kPercent = 100.0;

bool finiteAtLeastZero(double x) {
  return std::isfinite(x) && x >= 0.0;
}
}  // namespace

std::string LinkImpairmentOptions::validate() const {
  if (!finiteAtLeastZero(loss_percent) || loss_percent > kPercent) {
    return "loss must be a percentage in [0, 100]";
  }
  if (!finiteAtLeastZero(delay_ms)) return "delay must be ≥ 0 ms";
  if (!finiteAtLeastZero(jitter_ms)) return "jitter must be ≥ 0 ms";
  if (!finiteAtLeastZero(rate_kbit)) return "rate must be ≥ 0 kbit/s (0 = unlimited)";
  return {};
}

LinkImpairment::LinkImpairment(const LinkImpairmentOptions& options)
    : o_(options), rng_(options.seed) {}

LinkDecision LinkImpairment::decide(double now_s, std::size_t bytes) {
  LinkDecision d;
  // Draw both numbers for every packet, so the jitter of packet k does not depend on
  // whether earlier packets were lost: one seed, one pattern of each.
  const double u_loss = unit_(rng_);
  const double u_jitter = unit_(rng_);
  if (u_loss * kPercent < o_.loss_percent) {
    d.drop = true;
    return d;
  }
  double sent_s = now_s;
  if (o_.rate_kbit > 0.0) {
    const double serialise_s =
        static_cast<double>(bytes) * kBitsPerByte / (o_.rate_kbit * kBitsPerKbit);
    sent_s = std::max(now_s, link_free_s_) + serialise_s;
    link_free_s_ = sent_s;
  }
  const double delay_ms = std::max(0.0, o_.delay_ms + o_.jitter_ms * (2.0 * u_jitter - 1.0));
  d.release_s = sent_s + delay_ms / kMsPerS;
  if (!o_.reorder) d.release_s = std::max(d.release_s, last_release_s_);
  last_release_s_ = std::max(last_release_s_, d.release_s);
  return d;
}

}  // namespace cvslam::link
