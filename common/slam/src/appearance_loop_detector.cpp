#include "cvslam/slam/appearance_loop_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvslam/core/random.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

Status LoopDetectionOptions::load(const ConfigNode& node) {
  node.get("enabled", enabled);
  node.get("every_n_frames", every_n_frames);
  node.get("max_descriptor_distance", max_descriptor_distance);
  node.get("dist_ratio", dist_ratio);
  node.get("max_word_landmarks", max_word_landmarks);
  node.get("search_sigma_scale", search_sigma_scale);
  node.get("min_search_radius_m", min_search_radius_m);
  node.get("max_offset_m", max_offset_m);
  node.get("max_correction_sigmas", max_correction_sigmas);
  node.get("ransac_iterations", ransac_iterations);
  node.get("inlier_distance_m", inlier_distance_m);
  node.get("min_inliers", min_inliers);
  node.get("max_rms_m", max_rms_m);
  node.get("max_yaw_deg", max_yaw_deg);
  node.get("min_pair_separation_m", min_pair_separation_m);
  node.check(every_n_frames >= 1, "every_n_frames", "must be ≥ 1");
  node.check(max_descriptor_distance > 0.0, "max_descriptor_distance", "must be > 0");
  node.check(dist_ratio > 0.0 && dist_ratio <= 1.0, "dist_ratio", "must be in (0, 1]");
  node.check(max_word_landmarks >= 1, "max_word_landmarks", "must be ≥ 1");
  node.check(search_sigma_scale > 0.0, "search_sigma_scale", "must be > 0");
  node.check(min_search_radius_m > 0.0, "min_search_radius_m", "must be > 0");
  node.check(max_offset_m >= min_search_radius_m, "max_offset_m", "must be ≥ min_search_radius_m");
  node.check(max_correction_sigmas > 0.0, "max_correction_sigmas", "must be > 0");
  node.check(ransac_iterations >= 1, "ransac_iterations", "must be ≥ 1");
  node.check(inlier_distance_m > 0.0, "inlier_distance_m", "must be > 0");
  node.check(min_inliers >= 3, "min_inliers", "must be ≥ 3 (2 points always fit)");
  node.check(max_rms_m > 0.0, "max_rms_m", "must be > 0");
  node.check(max_yaw_deg > 0.0 && max_yaw_deg <= 180.0, "max_yaw_deg", "must be in (0, 180]");
  node.check(min_pair_separation_m >= 0.0, "min_pair_separation_m", "must be ≥ 0");
  return node.status();
}

namespace {

struct Candidate {
  std::size_t obs;
  int64_t landmark_id;
  double distance;
  LoopPair pair;
};

/// Indices of the candidates within `tolerance` of the fit.
std::vector<std::size_t> consensus(const std::vector<Candidate>& c, const LoopAlignment& fit,
                                   double tolerance) {
  std::vector<std::size_t> in;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if ((fit.apply(c[i].pair.p_observed_N) - c[i].pair.p_map_N).norm() <= tolerance) {
      in.push_back(i);
    }
  }
  return in;
}

/// Stage 1: appearance candidates — per observation, the closest archived descriptor of the
/// same word within the search radius (ratio-tested), plus observations the projection gate
/// already associated to a loop landmark; one observation per landmark, the closest kept.
std::vector<Candidate> appearanceCandidates(const std::vector<StereoObservation>& observations,
                                            const StereoCamera& camera,
                                            const LandmarkArchive& archive, const LoopQuery& query,
                                            const LoopDetectionOptions& o, double radius) {
  const auto min_seen_us = static_cast<int64_t>(query.min_last_seen_age_s * 1e6);
  const auto min_archived_us = static_cast<int64_t>(query.min_archived_age_s * 1e6);
  const double max_offset2 = radius * radius;
  std::vector<Candidate> candidates;
  auto loopAge = [&](const ArchivedLandmark& a) {
    return query.t_us - a.last_seen_us >= min_seen_us &&
           query.t_us - a.archived_us >= min_archived_us;
  };
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const StereoObservation& obs = observations[i];
    if (obs.landmark_id >= 0) {
      // Associated by the projection gate to a loop landmark: a candidate to verify too.
      const ArchivedLandmark* a = archive.find(obs.landmark_id);
      Eigen::Vector3d p_observed;
      if (a != nullptr && loopAge(*a) && camera.triangulate(obs.z, query.x_v, &p_observed).ok() &&
          (a->p_LinN - p_observed).squaredNorm() <= max_offset2) {
        candidates.push_back({i, obs.landmark_id, 0.0, {p_observed, a->p_LinN}});
      }
      continue;
    }
    if (obs.descriptor.empty()) continue;
    const std::vector<int64_t>& bucket = archive.withIndex(obs.index);
    if (bucket.empty() || static_cast<int>(bucket.size()) > o.max_word_landmarks) continue;
    Eigen::Vector3d p_observed;
    if (!camera.triangulate(obs.z, query.x_v, &p_observed).ok()) continue;
    const int bytes = static_cast<int>(obs.descriptor.size());
    double d1 = std::numeric_limits<double>::infinity(), d2 = d1;
    int64_t best = -1;
    const ArchivedLandmark* best_landmark = nullptr;
    for (int64_t id : bucket) {
      const ArchivedLandmark* a = archive.find(id);
      if (a == nullptr || static_cast<int>(a->descriptor.size()) != bytes) continue;
      if (!loopAge(*a)) continue;
      if ((a->p_LinN - p_observed).squaredNorm() > max_offset2) continue;
      const double d = vision::descriptorDistance(query.norm, obs.descriptor.data(),
                                                  a->descriptor.data(), bytes);
      if (d < d1 || (d == d1 && id < best)) {
        d2 = d1;
        d1 = d;
        best = id;
        best_landmark = a;
      } else if (d < d2) {
        d2 = d;
      }
    }
    if (best_landmark == nullptr || d1 > o.max_descriptor_distance) continue;
    if (std::isfinite(d2) && !(d1 < o.dist_ratio * d2)) continue;
    candidates.push_back({i, best, d1, {p_observed, best_landmark->p_LinN}});
  }
  // One observation per landmark: the closest descriptor keeps it.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.landmark_id < b.landmark_id ||
           (a.landmark_id == b.landmark_id &&
            (a.distance < b.distance || (a.distance == b.distance && a.obs < b.obs)));
  });
  candidates.erase(std::unique(candidates.begin(), candidates.end(),
                               [](const Candidate& a, const Candidate& b) {
                                 return a.landmark_id == b.landmark_id;
                               }),
                   candidates.end());
  return candidates;
}

/// Stage 2: RANSAC over pairs (a yaw + translation needs two points), rotating about the
/// vehicle; returns the largest consensus set.
std::vector<std::size_t> ransacConsensus(const std::vector<Candidate>& candidates,
                                         const Eigen::Vector3d& pivot,
                                         const LoopDetectionOptions& o) {
  const std::size_t n = candidates.size();
  const std::size_t all_pairs = n * (n - 1) / 2;
  const double min_sep2 = o.min_pair_separation_m * o.min_pair_separation_m;
  std::vector<std::size_t> best_set;
  auto tryPair = [&](std::size_t a, std::size_t b) {
    const LoopPair& pa = candidates[a].pair;
    const LoopPair& pb = candidates[b].pair;
    if ((pa.p_observed_N - pb.p_observed_N).head<2>().squaredNorm() < min_sep2) return;
    Expected<LoopAlignment> fit = alignLoop({pa, pb}, pivot);
    if (!fit.ok()) return;
    std::vector<std::size_t> in = consensus(candidates, *fit, o.inlier_distance_m);
    if (in.size() > best_set.size()) best_set.swap(in);
  };
  if (all_pairs <= static_cast<std::size_t>(o.ransac_iterations)) {
    for (std::size_t a = 0; a < n; ++a) {
      for (std::size_t b = a + 1; b < n; ++b) tryPair(a, b);
    }
  } else {
    Rng rng(n);  // seeded by the input: deterministic
    for (int t = 0; t < o.ransac_iterations; ++t) {
      const std::size_t a = rng.below(n);
      std::size_t b = rng.below(n - 1);
      if (b >= a) ++b;
      tryPair(a, b);
    }
  }
  return best_set;
}

}  // namespace

double AppearanceLoopDetector::searchRadius(double position_sigma_m) const {
  return std::clamp(o_.search_sigma_scale * position_sigma_m, o_.min_search_radius_m,
                    o_.max_offset_m);
}

LoopDetection AppearanceLoopDetector::detect(const std::vector<StereoObservation>& observations,
                                             const StereoCamera& camera,
                                             const LandmarkArchive& archive,
                                             const LoopQuery& query) const {
  LoopDetection out;
  if (!o_.enabled || archive.size() == 0) return out;
  // 1. Appearance candidates.
  const std::vector<Candidate> candidates = appearanceCandidates(
      observations, camera, archive, query, o_, searchRadius(query.position_sigma_m));
  out.candidates = static_cast<int>(candidates.size());
  if (static_cast<int>(candidates.size()) < o_.min_inliers) return out;
  // 2. Geometric consensus.
  const Eigen::Vector3d pivot = query.x_v.p_BinN;
  std::vector<std::size_t> best_set = ransacConsensus(candidates, pivot, o_);
  out.inliers = static_cast<int>(best_set.size());
  if (static_cast<int>(best_set.size()) < o_.min_inliers) return out;

  // 3. Refit on the consensus set, once more on its consensus, then the acceptance tests.
  for (int round = 0; round < 2; ++round) {
    std::vector<LoopPair> pairs;
    for (std::size_t i : best_set) pairs.push_back(candidates[i].pair);
    Expected<LoopAlignment> fit = alignLoop(pairs, pivot);
    if (!fit.ok()) return out;
    out.alignment = *fit;
    if (round == 0) best_set = consensus(candidates, *fit, o_.inlier_distance_m);
    if (static_cast<int>(best_set.size()) < o_.min_inliers) return out;
  }
  out.inliers = static_cast<int>(best_set.size());
  constexpr double kDegToRad = M_PI / 180.0;
  if (out.alignment.rms_residual > o_.max_rms_m ||
      std::abs(out.alignment.yaw) > o_.max_yaw_deg * kDegToRad) {
    return out;
  }
  // The correction of the vehicle (the pivot) must be plausible under its uncertainty: a
  // look-alike place farther away is rejected even when the search radius reached it.
  const double max_correction =
      std::max(o_.min_search_radius_m, o_.max_correction_sigmas * query.position_sigma_m);
  if (out.alignment.translation.head<2>().norm() > max_correction) return out;
  out.detected = true;
  for (std::size_t i : best_set) {
    out.matches.emplace_back(candidates[i].obs, candidates[i].landmark_id);
  }
  std::sort(out.matches.begin(), out.matches.end());
  return out;
}

}  // namespace cvslam
