#include "cvslam/sensors/sensor_event_orderer.h"

#include <utility>

namespace cvslam {

bool SensorEventOrderer::push(SensorEvent event, double arrival_s) {
  if (released_any_ &&
      (event.t_us < released_us_ || (event.t_us == released_us_ && event.type < released_type_))) {
    ++late_;
    return false;
  }
  if (event.type == SensorEventType::kImu && event.t_us > imu_up_to_us_) imu_up_to_us_ = event.t_us;
  const int64_t t = event.t_us;
  const SensorEventType type = event.type;
  pending_.insert(Item{t, type, next_order_++, arrival_s, std::move(event)});
  return true;
}

bool SensorEventOrderer::pop(double now_s, bool flush, SensorEvent* event, double* arrival_s) {
  if (pending_.empty()) return false;
  auto it = pending_.begin();
  const bool ready = flush || it->t_us <= imu_up_to_us_ || now_s - it->arrival_s >= o_.max_wait_s;
  if (!ready) return false;
  *event = std::move(it->event);
  if (arrival_s != nullptr) *arrival_s = it->arrival_s;
  released_us_ = it->t_us;
  released_type_ = it->type;
  released_any_ = true;
  pending_.erase(it);
  return true;
}

}  // namespace cvslam
