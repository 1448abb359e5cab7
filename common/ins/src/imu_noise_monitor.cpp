#include "cvslam/ins/imu_noise_monitor.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam {

Status ImuNoiseMonitorOptions::load(const ConfigNode& node) {
  node.get("measure_noise_density", enabled);
  node.get("noise_tau_s", tau_s);
  node.get("noise_window_s", window_s);
  node.check(tau_s > 0, "noise_tau_s", "must be > 0");
  node.check(window_s >= 4 * tau_s, "noise_window_s", "must be at least 4 × noise_tau_s");
  return node.status();
}

void ImuNoiseMonitor::add(const ImuSample& sample) {
  if (!o_.enabled || (started_ && sample.t_us <= last_us_)) return;
  if (!started_) {
    started_ = true;
    block_start_us_ = sample.t_us;
  }
  const int64_t tau_us = static_cast<int64_t>(std::llround(o_.tau_s * 1e6));
  if (count_ > 0 && sample.t_us - block_start_us_ >= tau_us) {
    // Close the block: its length runs to this sample, the start of the next.
    blocks_.push_back({sum_ / count_, 1e-6 * static_cast<double>(sample.t_us - block_start_us_)});
    sum_.setZero();
    count_ = 0;
    block_start_us_ = sample.t_us;
    if (blocks_.size() > 4) blocks_.pop_front();
    if (blocks_.size() == 4) {
      Term term;
      term.t_us = sample.t_us;
      term.d = blocks_[3].mean - 3.0 * blocks_[2].mean + 3.0 * blocks_[1].mean - blocks_[0].mean;
      term.tau_s = 0.25 * (blocks_[0].length_s + blocks_[1].length_s + blocks_[2].length_s +
                           blocks_[3].length_s);
      terms_.push_back(term);
    }
    const int64_t window_us = static_cast<int64_t>(std::llround(o_.window_s * 1e6));
    while (!terms_.empty() && sample.t_us - terms_.front().t_us > window_us) {
      terms_.pop_front();
    }
  }
  Vector6d x;
  x << sample.gyro_B, sample.accel_B;
  sum_ += x;
  ++count_;
  last_us_ = sample.t_us;
}

double ImuNoiseMonitor::density(int first_row) const {
  if (!ready()) return 0.0;
  // var(d) per axis from the median of d², robust to the sparse large terms a manoeuvre's
  // onset leaves (for Gaussian d, median(d²) = 0.4549 var(d)); averaged over the axes.
  constexpr double kMedianOfChiSquare1 = 0.454936;
  double var = 0.0;
  for (int i = first_row; i < first_row + 3; ++i) {
    scratch_.clear();
    for (const Term& t : terms_) scratch_.push_back(t.d(i) * t.d(i));
    const auto mid = scratch_.begin() + static_cast<std::ptrdiff_t>(scratch_.size() / 2);
    std::nth_element(scratch_.begin(), mid, scratch_.end());
    var += *mid / kMedianOfChiSquare1;
  }
  var /= 3.0;
  double tau = 0.0;
  for (const Term& t : terms_) tau += t.tau_s;
  tau /= static_cast<double>(terms_.size());
  return std::sqrt(var * tau / 20.0);
}

}  // namespace cvslam
