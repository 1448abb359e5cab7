#include "cvslam/simrun/cross_uav_match_audit.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include "cvslam/slam/visual_inertial_slam.h"
#include "cvslam/vision/descriptor_distance.h"

namespace cvslam::simrun {

double CrossUavMatchReport::precision() const {
  const long known = fused - fused_unknown;
  return known > 0 ? static_cast<double>(fused_right) / static_cast<double>(known) : 1.0;
}

double CrossUavMatchReport::recall() const {
  return distinct_twin_pairs > 0 ? static_cast<double>(distinct_twin_pairs_fused) /
                                       static_cast<double>(distinct_twin_pairs)
                                 : 0.0;
}

CrossUavMatchAudit::CrossUavMatchAudit(const CrossUavMatchAuditOptions& options) : o_(options) {}

CrossUavMatchAudit::PairKey CrossUavMatchAudit::key(int a, int64_t a_id, int b, int64_t b_id) {
  if (std::make_pair(b, b_id) < std::make_pair(a, a_id)) {
    std::swap(a, b);
    std::swap(a_id, b_id);
  }
  return {a, a_id, b, b_id};
}

void CrossUavMatchAudit::observe(int agent, int64_t t_us, const std::vector<StateLandmark>& own,
                                 const Truth& own_truth, int peer,
                                 const std::vector<StateLandmark>& peer_state,
                                 const Truth& peer_truth) {
  // The peer's truths once per call, not once per own landmark.
  std::vector<std::pair<const StateLandmark*, Eigen::Vector3d>> theirs;
  theirs.reserve(peer_state.size());
  for (const StateLandmark& l : peer_state) {
    Eigen::Vector3d p;
    if (peer_truth(l.id, &p)) theirs.emplace_back(&l, p);
  }
  for (const StateLandmark& mine : own) {
    if (mine.last_seen_us != t_us) continue;
    Eigen::Vector3d p_mine;
    if (!own_truth(mine.id, &p_mine)) continue;
    for (const auto& [twin, p_twin] : theirs) {
      if ((p_twin - p_mine).norm() > o_.twin_radius_m) continue;
      ++report_.twin_observations;
      twins_.insert(key(agent, mine.id, peer, twin->id));
      if (twin->index != mine.index) continue;
      ++report_.twin_same_index;
      const bool comparable =
          !mine.descriptor.empty() && mine.descriptor.size() == twin->descriptor.size();
      const double distance = comparable ? std::sqrt(static_cast<double>(vision::distanceL2Squared(
                                               mine.descriptor.data(), twin->descriptor.data(),
                                               static_cast<int>(mine.descriptor.size()))))
                                         : 0.0;
      if (distance <= o_.max_descriptor_distance) ++report_.twin_descriptor_ok;
    }
  }
  report_.distinct_twin_pairs = static_cast<long>(twins_.size());
}

void CrossUavMatchAudit::fused(int agent, int64_t own_id, const Truth& own_truth, int peer,
                               int64_t peer_id, const Truth& peer_truth) {
  ++report_.fused;
  Eigen::Vector3d p_own, p_peer;
  if (peer_id < 0 || !own_truth(own_id, &p_own) || !peer_truth(peer_id, &p_peer)) {
    ++report_.fused_unknown;
    return;
  }
  if ((p_own - p_peer).norm() > o_.twin_radius_m) return;
  ++report_.fused_right;
  // A pair fused that was never seen as an opportunity (the twin left the view before the
  // exchange completed) still counts as found.
  const PairKey k = key(agent, own_id, peer, peer_id);
  twins_.insert(k);
  twins_fused_.insert(k);
  report_.distinct_twin_pairs = static_cast<long>(twins_.size());
  report_.distinct_twin_pairs_fused = static_cast<long>(twins_fused_.size());
}

Json CrossUavMatchAudit::json() const {
  const CrossUavMatchReport& r = report_;
  Json j;
  j["twin_radius_m"] = o_.twin_radius_m;
  j["twin_observations"] = r.twin_observations;
  j["twin_same_index"] = r.twin_same_index;
  j["twin_descriptor_ok"] = r.twin_descriptor_ok;
  j["distinct_twin_pairs"] = r.distinct_twin_pairs;
  j["fused"] = r.fused;
  j["fused_right"] = r.fused_right;
  j["fused_unknown"] = r.fused_unknown;
  j["distinct_twin_pairs_fused"] = r.distinct_twin_pairs_fused;
  j["precision"] = r.precision();
  j["recall"] = r.recall();
  return j;
}

std::string CrossUavMatchAudit::summaryLine() const {
  const CrossUavMatchReport& r = report_;
  const auto pct = [](long a, long b) { return b > 0 ? 100.0 * a / b : 0.0; };
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "cross-UAV matches against the truth: %ld twin pairs in view (%ld observations, "
                "%.0f %% same index, %.0f %% also within the descriptor gate); fused %ld pairs, "
                "%ld right (precision %.1f %%, %ld without truth), recall %.1f %%",
                r.distinct_twin_pairs, r.twin_observations,
                pct(r.twin_same_index, r.twin_observations),
                pct(r.twin_descriptor_ok, r.twin_observations), r.fused, r.fused_right,
                100.0 * r.precision(), r.fused_unknown, 100.0 * r.recall());
  return buf;
}

}  // namespace cvslam::simrun
