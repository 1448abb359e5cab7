#pragma once
// The landmark book of one vehicle's map: what the filter keeps about each of its landmarks in
// the state besides the mean and covariance (those live in SlamState), and the vehicle-side
// bookkeeping those records depend on.
//
// Per landmark: feature index (visual word / true id), first and last time seen, descriptor,
// first estimate (first-estimates Jacobians), OC yaw direction u_L and whether the OC
// projection applies (observability_constraint.h), and whether it is a loop landmark waiting
// for a loop closure (§5.5.2, loop_closer.h). Per vehicle: its OC yaw direction u_v, carried
// by the INS transitions, from which every u_L of the book is derived.
// A landmark of the state is in exactly one vehicle's book; archived landmarks keep their
// record in the LandmarkArchive (landmark_archive.h).

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include "cvslam/filter/slam_state.h"

namespace cvslam {

/// One landmark of the book.
struct LandmarkBookEntry {
  uint32_t index = 0;  ///< feature index (visual word, or true id in feature-level simulation)
  int64_t first_seen_us = 0;
  int64_t last_seen_us = 0;
  std::vector<uint8_t> descriptor;                           ///< empty: none
  Eigen::Vector3d first_estimate = Eigen::Vector3d::Zero();  ///< p_LinN when (re)entering
  Eigen::Vector3d yaw_direction = Eigen::Vector3d::Zero();   ///< u_L (OC-EKF)
  /// OC-EKF applies: the landmark entered by augmentation, correlated with the vehicle. A
  /// re-activated landmark re-enters without correlation, as an independent prior on its
  /// absolute position, so the joint null space no longer contains it.
  bool constrained = false;
  /// The landmark drifted with this book's vehicle (it mapped it), so a loop closure moves it
  /// with the vehicle (loop_closer.h). false for another vehicle's landmark in a joint state
  /// (coop/cc_team_filter.h): it is in that vehicle's frame, like the loop landmarks.
  bool drifts_with_vehicle = true;
};

class LandmarkBook {
 public:
  /// Forgets every landmark, pending loop and the vehicle's yaw direction.
  void clear();

  LandmarkBookEntry* find(int64_t landmark_id);
  const LandmarkBookEntry* find(int64_t landmark_id) const;
  /// Records a landmark entering the state (or replaces its record).
  void add(int64_t landmark_id, LandmarkBookEntry record);
  /// Removes a landmark leaving the state, with its pending loop state; its record, if any.
  std::optional<LandmarkBookEntry> remove(int64_t landmark_id);

  /// The variables of this vehicle's map in `state`, in state order: the vehicle and the
  /// landmarks of the book.
  std::vector<VariableKey> variablesIn(const SlamState& state, const VariableKey& vehicle) const;

  /// u_v of the vehicle (observability_constraint.h).
  const Eigen::VectorXd& vehicleYawDirection() const { return vehicle_yaw_direction_; }
  void setVehicleYawDirection(const Eigen::VectorXd& u_v) { vehicle_yaw_direction_ = u_v; }

  /// Loop landmarks (§5.5.2): seen again after a long absence, since `since_us`, not yet used
  /// to close a loop. Marking an already pending landmark keeps its first time.
  void markPendingLoop(int64_t landmark_id, int64_t since_us);
  bool isPendingLoop(int64_t landmark_id) const { return pending_loop_.count(landmark_id) > 0; }
  void endPendingLoop(int64_t landmark_id) { pending_loop_.erase(landmark_id); }
  /// Ends the pending loops older than `window_us` at `now_us`.
  void expirePendingLoops(int64_t now_us, int64_t window_us);

 private:
  std::unordered_map<int64_t, LandmarkBookEntry> records_;
  std::map<int64_t, int64_t> pending_loop_;  // landmark id -> pending since [µs]
  Eigen::VectorXd vehicle_yaw_direction_;
};

}  // namespace cvslam
