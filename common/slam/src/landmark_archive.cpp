#include "cvslam/slam/landmark_archive.h"

#include <algorithm>
#include <utility>

namespace cvslam {

void LandmarkArchive::store(int64_t landmark_id, ArchivedLandmark landmark) {
  auto it = landmarks_.find(landmark_id);
  if (it != landmarks_.end()) unindex(landmark_id, it->second.index);
  by_index_[landmark.index].push_back(landmark_id);
  landmarks_[landmark_id] = std::move(landmark);
}

void LandmarkArchive::unindex(int64_t landmark_id, uint32_t index) {
  auto bucket = by_index_.find(index);
  if (bucket == by_index_.end()) return;
  std::vector<int64_t>& ids = bucket->second;
  auto pos = std::find(ids.begin(), ids.end(), landmark_id);
  if (pos != ids.end()) {
    *pos = ids.back();
    ids.pop_back();
  }
  if (ids.empty()) by_index_.erase(bucket);
}

const std::vector<int64_t>& LandmarkArchive::withIndex(uint32_t index) const {
  static const std::vector<int64_t> kNone;
  auto bucket = by_index_.find(index);
  return bucket == by_index_.end() ? kNone : bucket->second;
}

std::optional<ArchivedLandmark> LandmarkArchive::take(int64_t landmark_id) {
  auto it = landmarks_.find(landmark_id);
  if (it == landmarks_.end()) return std::nullopt;
  unindex(landmark_id, it->second.index);
  ArchivedLandmark out = std::move(it->second);
  landmarks_.erase(it);
  return out;
}

const ArchivedLandmark* LandmarkArchive::find(int64_t landmark_id) const {
  auto it = landmarks_.find(landmark_id);
  return it == landmarks_.end() ? nullptr : &it->second;
}

}  // namespace cvslam
