#pragma once
// One agent's sensor events arrive on several channels (UAV<id>/IMU, /GT, /STEREO or
// /FEATURES), each in order but interleaved arbitrarily; the filter needs them in dataset-time
// order, IMU before ground truth before the frame at equal times (sensor_stream.h). The
// orderer holds what arrived and releases an event once nothing earlier can still come:
// when the IMU (the fastest stream, published first at each instant by cvslam_replay) has
// reached its time, or when it has waited `max_wait_s` of wall time (a gap in the IMU, or the
// end of the stream). An event older than one already released is late: it is dropped and
// counted (the filter cannot go back in time).

#include <cstdint>
#include <set>

#include "cvslam/sensors/sensor_stream.h"

namespace cvslam {

struct SensorEventOrdererOptions {
  double max_wait_s = 0.3;  ///< release an event after this long even without IMU past it [s]
};

class SensorEventOrderer {
 public:
  explicit SensorEventOrderer(const SensorEventOrdererOptions& options = {}) : o_(options) {}

  /// Adds an event that arrived at wall time `arrival_s` [s]; false (dropped, counted) if
  /// it is older than an event already released.
  bool push(SensorEvent event, double arrival_s);
  /// The next event that is ready at wall time `now_s`; `flush`: everything is ready (end
  /// of stream, shutdown). False when none is.
  bool pop(double now_s, bool flush, SensorEvent* event, double* arrival_s);

  std::size_t size() const { return pending_.size(); }
  int64_t late() const { return late_; }
  /// Dataset time of the latest released event (−1: none yet) [µs].
  int64_t releasedUpTo() const { return released_us_; }

 private:
  struct Item {
    int64_t t_us;
    SensorEventType type;
    uint64_t order;  // arrival order among equal keys
    double arrival_s;
    mutable SensorEvent event;  // moved out on release; not part of the key
    bool operator<(const Item& o) const {
      if (t_us != o.t_us) return t_us < o.t_us;
      if (type != o.type) return type < o.type;
      return order < o.order;
    }
  };

  SensorEventOrdererOptions o_;
  std::set<Item> pending_;
  uint64_t next_order_ = 0;
  int64_t imu_up_to_us_ = INT64_MIN;
  int64_t released_us_ = -1;
  SensorEventType released_type_ = SensorEventType::kImu;
  bool released_any_ = false;
  int64_t late_ = 0;
};

}  // namespace cvslam
