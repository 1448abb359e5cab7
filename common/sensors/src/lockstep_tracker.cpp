#include "cvslam/sensors/lockstep_tracker.h"

#include <algorithm>

namespace cvslam {
namespace {

bool isFrame(SensorEventType type) {
  return type == SensorEventType::kStereoImage || type == SensorEventType::kFeatures;
}

}  // namespace

LockstepTracker::LockstepTracker(const std::vector<int>& participants,
                                 const std::vector<int>& agents)
    : agents_(agents.begin(), agents.end()) {
  for (int p : participants) required_[p] = kNothing;
}

bool LockstepTracker::startsNewEpoch(SensorEventType type, int64_t play_us) const {
  return frames_in_epoch_ && !(isFrame(type) && play_us == frame_play_us_);
}

void LockstepTracker::published(int agent_id, SensorEventType type, int64_t t_us, int64_t play_us) {
  auto it = open_max_.find(agent_id);
  if (it == open_max_.end()) {
    open_max_[agent_id] = t_us;
  } else {
    it->second = std::max(it->second, t_us);
  }
  open_max_all_ = std::max(open_max_all_, t_us);
  if (isFrame(type)) {
    frames_in_epoch_ = true;
    frame_play_us_ = play_us;
  }
}

void LockstepTracker::closeEpoch() {
  for (auto& [p, required] : required_) {
    if (agents_.count(p) > 0) {
      auto it = open_max_.find(p);
      if (it != open_max_.end()) required = std::max(required, it->second);
    } else {
      required = std::max(required, open_max_all_);
    }
  }
  open_max_.clear();
  open_max_all_ = kNothing;
  frames_in_epoch_ = false;
  ++epochs_closed_;
}

void LockstepTracker::onStatus(int id, int64_t processed_utime) {
  if (required_.count(id) == 0) return;
  auto it = processed_.find(id);
  if (it == processed_.end()) {
    processed_[id] = processed_utime;
  } else {
    it->second = std::max(it->second, processed_utime);  // reordered reports never regress
  }
}

std::vector<int> LockstepTracker::waitingFor() const {
  std::vector<int> waiting;
  for (const auto& [p, required] : required_) {
    auto it = processed_.find(p);
    if (it == processed_.end() || (required != kNothing && it->second < required))
      waiting.push_back(p);
  }
  return waiting;
}

bool LockstepTracker::ready() const {
  return waitingFor().empty();
}

}  // namespace cvslam
