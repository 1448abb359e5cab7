#include "cvslam/slam/loop_alignment.h"

#include <cmath>

namespace cvslam {

Eigen::Vector3d LoopAlignment::apply(const Eigen::Vector3d& p) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const Eigen::Vector3d d = p - pivot;
  return pivot + translation + Eigen::Vector3d(c * d.x() - s * d.y(), s * d.x() + c * d.y(), d.z());
}

Expected<LoopAlignment> alignLoop(const std::vector<LoopPair>& pairs,
                                  const Eigen::Vector3d& pivot) {
  if (pairs.size() < 2) return Status::Error("loop alignment needs at least 2 landmarks");
  Eigen::Vector3d mean_obs = Eigen::Vector3d::Zero(), mean_map = Eigen::Vector3d::Zero();
  for (const LoopPair& p : pairs) {
    if (!p.p_observed_N.allFinite() || !p.p_map_N.allFinite()) {
      return Status::Error("loop alignment: non-finite landmark position");
    }
    mean_obs += p.p_observed_N - pivot;
    mean_map += p.p_map_N - pivot;
  }
  mean_obs /= static_cast<double>(pairs.size());
  mean_map /= static_cast<double>(pairs.size());
  // 2-D Procrustes on the horizontal components: the yaw maximising Σ ⟨R a_i, b_i⟩.
  double sum_dot = 0.0, sum_cross = 0.0, spread = 0.0;
  for (const LoopPair& p : pairs) {
    const Eigen::Vector2d a = (p.p_observed_N - pivot - mean_obs).head<2>();
    const Eigen::Vector2d b = (p.p_map_N - pivot - mean_map).head<2>();
    sum_dot += a.dot(b);
    sum_cross += a.x() * b.y() - a.y() * b.x();
    spread += a.squaredNorm();
  }
  LoopAlignment out;
  out.pivot = pivot;
  // Points (nearly) on top of each other give no yaw: keep it at zero.
  out.yaw = spread > 1e-6 ? std::atan2(sum_cross, sum_dot) : 0.0;
  const double c = std::cos(out.yaw), s = std::sin(out.yaw);
  const Eigen::Vector3d rotated_mean(c * mean_obs.x() - s * mean_obs.y(),
                                     s * mean_obs.x() + c * mean_obs.y(), mean_obs.z());
  out.translation = mean_map - rotated_mean;
  double sq = 0.0;
  for (const LoopPair& p : pairs) sq += (out.apply(p.p_observed_N) - p.p_map_N).squaredNorm();
  out.rms_residual = std::sqrt(sq / static_cast<double>(pairs.size()));
  return out;
}

}  // namespace cvslam
