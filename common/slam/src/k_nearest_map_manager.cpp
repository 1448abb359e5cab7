#include "cvslam/slam/k_nearest_map_manager.h"

#include <algorithm>
#include <tuple>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"

namespace cvslam {

Status MapManagerOptions::load(const ConfigNode& node) {
  node.getEnum("kind", kind, {{"knearest", MapKind::kKNearest}, {"full", MapKind::kFull}});
  node.get("k", k);
  node.get("nominal_scene_depth", nominal_scene_depth);
  node.get("use_observed_depth", use_observed_depth);
  node.check(k >= 1, "k", "must be ≥ 1 (got " + std::to_string(k) + ")");
  node.get("scene_depth_quantile", scene_depth_quantile);
  node.get("max_landmarks", max_landmarks);
  node.check(max_landmarks >= 0, "max_landmarks", "must be ≥ 0 (0: no bound)");
  node.check(nominal_scene_depth > 0.0, "nominal_scene_depth", "must be > 0");
  node.check(scene_depth_quantile >= 0.0 && scene_depth_quantile <= 1.0, "scene_depth_quantile",
             "must be in [0, 1]");
  return node.status();
}

Eigen::Vector3d KNearestMapManager::virtualPoint(const StereoCamera& camera,
                                                 const Eigen::Vector3d& p_BinN,
                                                 const Eigen::Matrix3d& R_BtoN, double depth) {
  const StereoCameraOptions& c = camera.options();
  // Midpoint of the optical centres, in the left camera frame, then along z_C.
  const Eigen::Vector3d m_inC(0.5 * c.baseline, 0.0, depth);
  const Eigen::Vector3d m_inB = c.R_BtoC.transpose() * m_inC + c.p_CinB;
  return p_BinN + R_BtoN * m_inB;
}

double KNearestMapManager::sceneDepth(const std::vector<double>& observed_depths) const {
  if (!o_.use_observed_depth || observed_depths.empty()) return o_.nominal_scene_depth;
  std::vector<double> d = observed_depths;
  const auto rank = std::min(d.size() - 1, static_cast<std::size_t>(o_.scene_depth_quantile *
                                                                    static_cast<double>(d.size())));
  auto mid = d.begin() + static_cast<std::ptrdiff_t>(rank);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

std::vector<int64_t> KNearestMapManager::select(const std::vector<MapCandidate>& candidates,
                                                const Eigen::Vector3d& m_star) const {
  // (group, key, id): re-observed archived, observed, unobserved; the key is the squared
  // distance to m* (k-nearest) or the time since last observed (full map).
  const bool full = o_.kind == MapKind::kFull;
  std::vector<std::tuple<int, double, int64_t>> ranked;
  ranked.reserve(candidates.size());
  for (const auto& c : candidates) {
    const int group = c.observed ? (c.reactivating ? 0 : 1) : 2;
    const double key =
        full ? -static_cast<double>(c.last_seen_us) : (c.p_LinN - m_star).squaredNorm();
    ranked.emplace_back(group, key, c.landmark_id);
  }
  std::size_t keep = ranked.size();
  const int bound = full ? o_.max_landmarks : o_.k;
  if (bound > 0) keep = std::min(keep, static_cast<std::size_t>(bound));
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep),
                    ranked.end());
  std::vector<int64_t> ids;
  ids.reserve(keep);
  for (std::size_t i = 0; i < keep; ++i) ids.push_back(std::get<2>(ranked[i]));
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace cvslam
