#pragma once
// Landmarks that left the filter state (thesis §5.8): "we propose to save all the observed
// landmarks, during the flight, with their respective covariance matrices. This will help
// in building a large map and to make the loop closing detection possible."
// An archived landmark that is re-observed is re-activated into the state (loop closing,
// §5.5.2) with the mean and marginal covariance it had when it was archived.
// The archive keeps an inverted index feature index (visual word) → landmarks, so that a
// frame can be matched against it by appearance (appearance_loop_detector.h; docs/conventions.md).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace cvslam {

struct ArchivedLandmark {
  uint32_t index = 0;                                       ///< feature index (word id / true id)
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();         ///< mean [m], NED
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();     ///< marginal covariance [m²]
  Eigen::Vector3d yaw_direction = Eigen::Vector3d::Zero();  ///< u_L (observability_constraint.h)
  int64_t first_seen_us = 0;                                ///< time it was initialised
  int64_t last_seen_us = 0;                                 ///< time it was last observed
  int64_t archived_us = 0;                                  ///< time it left the state
  std::vector<uint8_t> descriptor;                          ///< for appearance checks
  bool constrained = false;  ///< its book record's LandmarkBookEntry::constrained
  Eigen::Vector3d first_estimate = Eigen::Vector3d::Zero();  ///< and ::first_estimate
};

class LandmarkArchive {
 public:
  /// Stores (or replaces) a landmark that leaves the state.
  void store(int64_t landmark_id, ArchivedLandmark landmark);
  /// Removes and returns the landmark, if archived (re-activation).
  std::optional<ArchivedLandmark> take(int64_t landmark_id);
  const ArchivedLandmark* find(int64_t landmark_id) const;
  bool contains(int64_t landmark_id) const { return landmarks_.count(landmark_id) > 0; }
  std::size_t size() const { return landmarks_.size(); }
  const std::unordered_map<int64_t, ArchivedLandmark>& all() const { return landmarks_; }
  /// Ids of the archived landmarks with this feature index (empty if none), in no
  /// particular (but deterministic) order.
  const std::vector<int64_t>& withIndex(uint32_t index) const;

 private:
  void unindex(int64_t landmark_id, uint32_t index);

  std::unordered_map<int64_t, ArchivedLandmark> landmarks_;
  std::unordered_map<uint32_t, std::vector<int64_t>> by_index_;
};

}  // namespace cvslam
