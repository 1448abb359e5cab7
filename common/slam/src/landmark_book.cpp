#include "cvslam/slam/landmark_book.h"

namespace cvslam {

void LandmarkBook::clear() {
  records_.clear();
  pending_loop_.clear();
  vehicle_yaw_direction_ = Eigen::VectorXd();
}

LandmarkBookEntry* LandmarkBook::find(int64_t landmark_id) {
  auto it = records_.find(landmark_id);
  return it == records_.end() ? nullptr : &it->second;
}

const LandmarkBookEntry* LandmarkBook::find(int64_t landmark_id) const {
  auto it = records_.find(landmark_id);
  return it == records_.end() ? nullptr : &it->second;
}

void LandmarkBook::add(int64_t landmark_id, LandmarkBookEntry record) {
  records_[landmark_id] = std::move(record);
}

std::optional<LandmarkBookEntry> LandmarkBook::remove(int64_t landmark_id) {
  pending_loop_.erase(landmark_id);
  auto it = records_.find(landmark_id);
  if (it == records_.end()) return std::nullopt;
  LandmarkBookEntry out = std::move(it->second);
  records_.erase(it);
  return out;
}

std::vector<VariableKey> LandmarkBook::variablesIn(const SlamState& state,
                                                   const VariableKey& vehicle) const {
  std::vector<VariableKey> out;
  for (const StateVariable& v : state.variables()) {
    const bool mine = v.key.kind == VariableKey::Kind::kVehicle
                          ? v.key == vehicle
                          : records_.count(static_cast<int64_t>(v.key.id)) > 0;
    if (mine) out.push_back(v.key);
  }
  return out;
}

void LandmarkBook::markPendingLoop(int64_t landmark_id, int64_t since_us) {
  pending_loop_.emplace(landmark_id, since_us);
}

void LandmarkBook::expirePendingLoops(int64_t now_us, int64_t window_us) {
  for (auto it = pending_loop_.begin(); it != pending_loop_.end();) {
    it = now_us - it->second > window_us ? pending_loop_.erase(it) : std::next(it);
  }
}

}  // namespace cvslam
