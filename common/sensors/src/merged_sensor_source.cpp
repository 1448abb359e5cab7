#include "cvslam/sensors/merged_sensor_source.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cvslam {

MergedSensorSource::MergedSensorSource(std::vector<std::unique_ptr<AgentSensorStream>> agents,
                                       PlayWindow window)
    : agents_(std::move(agents)), heads_(agents_.size()) {
  start_us_ = std::llround(window.start * 1e6);
  int64_t longest = 0;
  for (const auto& a : agents_) longest = std::max(longest, a->endPlayUs());
  end_us_ =
      window.duration > 0.0
          ? std::min(longest, start_us_ + static_cast<int64_t>(std::llround(window.duration * 1e6)))
          : longest;
}

std::vector<int> MergedSensorSource::agentIds() const {
  std::vector<int> ids;
  for (const auto& a : agents_) ids.push_back(a->agentId());
  return ids;
}

bool MergedSensorSource::refill(std::size_t i) {
  SensorEvent e;
  // Skip what lies before the window; agent streams are cheap to skip only until they
  // render or decode, which is why EuRoC streams also take the start (euroc_sensor_stream.h).
  while (agents_[i]->next(e)) {
    if (e.play_us < start_us_) continue;
    if (e.play_us > end_us_) break;
    heads_[i] = std::move(e);
    return true;
  }
  heads_[i].reset();
  if (!agents_[i]->status().ok() && status_.ok()) status_ = agents_[i]->status();
  return false;
}

bool MergedSensorSource::next(SensorEvent& event) {
  if (!primed_) {
    for (std::size_t i = 0; i < agents_.size(); ++i) refill(i);
    primed_ = true;
  }
  if (!status_.ok()) return false;
  std::size_t best = heads_.size();
  for (std::size_t i = 0; i < heads_.size(); ++i) {
    if (!heads_[i]) continue;
    if (best == heads_.size() ||
        eventBefore(heads_[i]->play_us, heads_[i]->type, heads_[i]->agent_id, heads_[best]->play_us,
                    heads_[best]->type, heads_[best]->agent_id)) {
      best = i;
    }
  }
  if (best == heads_.size()) return false;
  event = std::move(*heads_[best]);
  refill(best);
  return status_.ok();
}

}  // namespace cvslam
