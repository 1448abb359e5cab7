#include "cvslam/filter/slam_state.h"

#include <algorithm>

namespace cvslam {

const StateVariable* SlamState::find(const VariableKey& key) const {
  const auto it = slot_.find(key);
  return it == slot_.end() ? nullptr : &vars_[static_cast<std::size_t>(it->second)];
}

const VariableKey* SlamState::landmarkAnchor(const VariableKey& landmark) const {
  const auto it = anchor_.find(landmark);
  return it == anchor_.end() ? nullptr : &it->second;
}

const Eigen::Quaterniond* SlamState::nominalAttitude(const VariableKey& vehicle) const {
  const auto it = nominal_.find(vehicle);
  return it == nominal_.end() ? nullptr : &it->second;
}

int SlamState::count(VariableKey::Kind kind) const {
  return static_cast<int>(std::count_if(
      vars_.begin(), vars_.end(), [kind](const StateVariable& v) { return v.key.kind == kind; }));
}

}  // namespace cvslam
