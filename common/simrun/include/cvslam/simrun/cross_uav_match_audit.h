#pragma once
// Cross-UAV landmark matches of DC-VSLAM checked against the simulator's truth
// (docs/cooperation.md "Cross-UAV matches against the
// truth"). Two landmarks of two UAVs are TWINS when their true positions (the feature's true id
// with features; the surface the renderer showed where each was initialised with images) are
// within `twin_radius_m`. The audit counts
//   - the opportunities: each frame, each landmark a UAV observes that has a twin in a peer's
//     state at that moment, whether the twin carries the same feature index (the protocol can
//     only find it then) and passes the descriptor check;
//   - the matches DC fused (coop::FusedMatch): a fused pair is right when it is a pair of twins.
// precision = right / fused pairs whose truth is known; recall = distinct twin pairs fused /
// distinct twin pairs that were in view.
// A CROSSING of two UAVs is a maximal stretch of time over which either observes a landmark
// whose true position is within `crossing_radius_m` of the true position of one of the other's
// state landmarks (whether or not the two are twins), with no gap longer than `crossing_gap_s`:
// the times one views ground the other has mapped. A crossing is fused when a right pair of the
// two is fused during it or within `crossing_gap_s` after it (the exchange's latency).

#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>

#include "cvslam/io/json_file.h"

namespace cvslam {
struct StateLandmark;
}

namespace cvslam::simrun {

struct CrossUavMatchAuditOptions {
  double twin_radius_m = 0.1;  ///< true positions this close are the same surface point [m]
  /// The protocol's descriptor check (coop.max_descriptor_distance): L2 over descriptor bytes.
  double max_descriptor_distance = 250.0;
  /// A landmark observed this close to a peer's state landmark is over the peer's map [m].
  double crossing_radius_m = 1.0;
  /// Frames over the peer's map this far apart in time belong to two crossings [s].
  double crossing_gap_s = 2.0;
};

/// One crossing of two UAVs (uav_a < uav_b).
struct Crossing {
  int uav_a = 0, uav_b = 0;
  int64_t start_us = 0, end_us = 0;  ///< first and last frame over the other's map [µs]
  long frames = 0;                   ///< frames of either UAV over the other's map
  long fused_right = 0;  ///< right pairs of the two fused during it (or up to the gap after)
};

struct CrossUavMatchReport {
  long twin_observations = 0;   ///< (frame, landmark in view, peer) with a twin in the peer's state
  long twin_same_index = 0;     ///< ... whose twin has the same feature index
  long twin_descriptor_ok = 0;  ///< ... and passes the descriptor check too
  long distinct_twin_pairs = 0;  ///< distinct twin pairs ever in view
  long fused = 0;                ///< landmark pairs fused (both directions of an exchange)
  long fused_right = 0;          ///< ... that are twins
  long fused_unknown = 0;        ///< ... without truth for one of the two landmarks
  long distinct_twin_pairs_fused = 0;
  long crossings = 0;        ///< crossings of every pair of UAVs
  long crossings_fused = 0;  ///< ... with at least one right pair fused
  /// Right / fused with known truth; 1 when nothing was fused.
  double precision() const;
  /// Distinct twin pairs fused / in view; 0 when none was in view.
  double recall() const;
};

class CrossUavMatchAudit {
 public:
  /// The true position of a landmark of one UAV; false when unknown.
  using Truth = std::function<bool(int64_t landmark_id, Eigen::Vector3d* p_LinN)>;

  explicit CrossUavMatchAudit(const CrossUavMatchAuditOptions& options = {});

  /// The landmarks of UAV `agent` observed at t_us (StateLandmark::last_seen_us == t_us) against
  /// the state of UAV `peer`.
  void observe(int agent, int64_t t_us, const std::vector<StateLandmark>& own,
               const Truth& own_truth, int peer, const std::vector<StateLandmark>& peer_state,
               const Truth& peer_truth);
  /// One fused pair: the own landmark of `agent` and the landmark `peer_id` of `peer` (-1:
  /// unknown), fused at t_us (-1: unknown, then it is attributed to no crossing).
  void fused(int agent, int64_t own_id, const Truth& own_truth, int peer, int64_t peer_id,
             const Truth& peer_truth, int64_t t_us = -1);

  const CrossUavMatchReport& report() const { return report_; }
  /// Every crossing so far, by pair of UAVs and then time.
  std::vector<Crossing> crossings() const;
  /// The report as a JSON object (cross_uav_matches.json, docs/run_format.md).
  Json json() const;
  /// One line for a run summary.
  std::string summaryLine() const;

 private:
  /// Unordered pair of (agent, landmark) ids.
  using PairKey = std::tuple<int, int64_t, int, int64_t>;
  static PairKey key(int a, int64_t a_id, int b, int64_t b_id);
  /// crossing_gap_s [µs].
  int64_t gapUs() const;
  /// A frame of UAV a over b's map at t_us: extends their last crossing or opens one.
  void countCrossing(int a, int b, int64_t t_us);
  /// The crossing of a and b that a right pair fused at t_us belongs to; null if none.
  Crossing* crossingAt(int a, int b, int64_t t_us);

  CrossUavMatchAuditOptions o_;
  CrossUavMatchReport report_;
  std::set<PairKey> twins_;
  std::set<PairKey> twins_fused_;
  std::map<std::pair<int, int>, std::vector<Crossing>> crossings_;  ///< by (uav_a < uav_b)
};

}  // namespace cvslam::simrun
