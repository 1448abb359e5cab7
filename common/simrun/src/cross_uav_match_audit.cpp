#include "cvslam/simrun/cross_uav_match_audit.h"

#include <algorithm>
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

int64_t CrossUavMatchAudit::gapUs() const {
  return static_cast<int64_t>(std::llround(o_.crossing_gap_s * 1e6));
}

void CrossUavMatchAudit::countCrossing(int a, int b, int64_t t_us) {
  std::vector<Crossing>& list = crossings_[std::minmax(a, b)];
  if (list.empty() || t_us - list.back().end_us > gapUs()) {
    Crossing c;
    std::tie(c.uav_a, c.uav_b) = std::minmax(a, b);
    c.start_us = c.end_us = t_us;
    list.push_back(c);
    ++report_.crossings;
  }
  Crossing& c = list.back();
  c.end_us = std::max(c.end_us, t_us);
  ++c.frames;
}

Crossing* CrossUavMatchAudit::crossingAt(int a, int b, int64_t t_us) {
  if (t_us < 0) return nullptr;
  auto it = crossings_.find(std::minmax(a, b));
  if (it == crossings_.end()) return nullptr;
  for (auto c = it->second.rbegin(); c != it->second.rend(); ++c) {
    if (t_us >= c->start_us && t_us <= c->end_us + gapUs()) return &*c;
  }
  return nullptr;
}

std::vector<Crossing> CrossUavMatchAudit::crossings() const {
  std::vector<Crossing> out;
  for (const auto& [pair, list] : crossings_) out.insert(out.end(), list.begin(), list.end());
  return out;
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
  bool over_peer_map = false;
  for (const StateLandmark& mine : own) {
    if (mine.last_seen_us != t_us) continue;
    Eigen::Vector3d p_mine;
    if (!own_truth(mine.id, &p_mine)) continue;
    for (const auto& [twin, p_twin] : theirs) {
      const double d = (p_twin - p_mine).norm();
      if (d <= o_.crossing_radius_m) over_peer_map = true;
      if (d > o_.twin_radius_m) continue;
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
  if (over_peer_map) countCrossing(agent, peer, t_us);
}

void CrossUavMatchAudit::fused(int agent, int64_t own_id, const Truth& own_truth, int peer,
                               int64_t peer_id, const Truth& peer_truth, int64_t t_us) {
  ++report_.fused;
  Eigen::Vector3d p_own, p_peer;
  if (peer_id < 0 || !own_truth(own_id, &p_own) || !peer_truth(peer_id, &p_peer)) {
    ++report_.fused_unknown;
    return;
  }
  if ((p_own - p_peer).norm() > o_.twin_radius_m) return;
  ++report_.fused_right;
  if (Crossing* c = crossingAt(agent, peer, t_us)) {
    if (c->fused_right++ == 0) ++report_.crossings_fused;
  }
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
  j["crossing_radius_m"] = o_.crossing_radius_m;
  j["crossing_gap_s"] = o_.crossing_gap_s;
  j["crossings_fused"] = r.crossings_fused;
  Json list = Json::array();
  for (const Crossing& c : crossings()) {
    Json e;
    e["uavs"] = {c.uav_a, c.uav_b};
    e["start_s"] = static_cast<double>(c.start_us) * 1e-6;
    e["end_s"] = static_cast<double>(c.end_us) * 1e-6;
    e["frames"] = c.frames;
    e["fused_right"] = c.fused_right;
    list.push_back(e);
  }
  j["crossings"] = list;
  return j;
}

std::string CrossUavMatchAudit::summaryLine() const {
  const CrossUavMatchReport& r = report_;
  const auto pct = [](long a, long b) { return b > 0 ? 100.0 * a / b : 0.0; };
  char buf[512];
  std::snprintf(
      buf, sizeof(buf),
      "cross-UAV matches against the truth: %ld twin pairs in view (%ld observations, "
      "%.0f %% same index, %.0f %% also within the descriptor gate); fused %ld pairs, "
      "%ld right (precision %.1f %%, %ld without truth), recall %.1f %%; %ld of %ld "
      "crossings with a right pair fused",
      r.distinct_twin_pairs, r.twin_observations, pct(r.twin_same_index, r.twin_observations),
      pct(r.twin_descriptor_ok, r.twin_observations), r.fused, r.fused_right, 100.0 * r.precision(),
      r.fused_unknown, 100.0 * r.recall(), r.crossings_fused, r.crossings);
  return buf;
}

}  // namespace cvslam::simrun
