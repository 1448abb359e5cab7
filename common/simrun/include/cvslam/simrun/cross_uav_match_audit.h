#pragma once
// Cross-UAV landmark matches of DC-VSLAM checked against the simulator's truth (issue #14,
// "image-level cooperation that happens"; docs/cooperation.md "Cross-UAV matches against the
// truth"). Two landmarks of two UAVs are TWINS when their true positions (the feature's true id
// with features; the surface the renderer showed where each was initialised with images) are
// within `twin_radius_m`. The audit counts
//   - the opportunities: each frame, each landmark a UAV observes that has a twin in a peer's
//     state at that moment, whether the twin carries the same feature index (the protocol can
//     only find it then) and passes the descriptor check;
//   - the matches DC fused (coop::FusedMatch): a fused pair is right when it is a pair of twins.
// precision = right / fused pairs whose truth is known; recall = distinct twin pairs fused /
// distinct twin pairs that were in view.

#include <cstdint>
#include <functional>
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
  /// unknown).
  void fused(int agent, int64_t own_id, const Truth& own_truth, int peer, int64_t peer_id,
             const Truth& peer_truth);

  const CrossUavMatchReport& report() const { return report_; }
  /// The report as a JSON object (cross_uav_matches.json, docs/run_format.md).
  Json json() const;
  /// One line for a run summary.
  std::string summaryLine() const;

 private:
  /// Unordered pair of (agent, landmark) ids.
  using PairKey = std::tuple<int, int64_t, int, int64_t>;
  static PairKey key(int a, int64_t a_id, int b, int64_t b_id);

  CrossUavMatchAuditOptions o_;
  CrossUavMatchReport report_;
  std::set<PairKey> twins_;
  std::set<PairKey> twins_fused_;
};

}  // namespace cvslam::simrun
