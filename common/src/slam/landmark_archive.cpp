#include "cvslam/slam/landmark_archive.h"

#include <utility>

namespace cvslam {

void LandmarkArchive::store(int64_t landmark_id, ArchivedLandmark landmark) {
  landmarks_[landmark_id] = std::move(landmark);
}

std::optional<ArchivedLandmark> LandmarkArchive::take(int64_t landmark_id) {
  auto it = landmarks_.find(landmark_id);
  if (it == landmarks_.end()) return std::nullopt;
  ArchivedLandmark out = std::move(it->second);
  landmarks_.erase(it);
  return out;
}

const ArchivedLandmark* LandmarkArchive::find(int64_t landmark_id) const {
  auto it = landmarks_.find(landmark_id);
  return it == landmarks_.end() ? nullptr : &it->second;
}

}  // namespace cvslam
