#include "cvslam/sim/observation_simulator.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

ObservationSimulator::ObservationSimulator(const StereoCameraOptions& camera,
                                           const PixelNoiseOptions& options, uint64_t seed)
    : camera_(camera), o_(options), rng_(seed) {}

Eigen::AlignedBox2d ObservationSimulator::searchBox(const Eigen::Vector3d& p_CinN,
                                                    const Eigen::Matrix3d& R_CtoN,
                                                    const World& world) const {
  // Bounding box of the view frustum between the lowest and highest landmark heights: the
  // image-corner rays of both cameras cut at those two planes (or at max_range).
  const StereoCameraOptions& c = camera_.options();
  Eigen::AlignedBox2d box;
  const Eigen::Vector3d right_centre = p_CinN + R_CtoN * Eigen::Vector3d(c.baseline, 0.0, 0.0);
  const double us[2] = {0.0, static_cast<double>(c.width)};
  const double vs[2] = {0.0, static_cast<double>(c.height)};
  for (const Eigen::Vector3d& centre : {p_CinN, right_centre}) {
    box.extend(centre.head<2>());
    for (double u : us) {
      for (double v : vs) {
        const Eigen::Vector3d d = R_CtoN * Eigen::Vector3d((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1);
        const double lambda_max = o_.max_range / d.norm();
        for (double z_plane : {world.minZ(), world.maxZ()}) {
          double lambda = lambda_max;
          if (d.z() > 1e-9) lambda = std::clamp((z_plane - centre.z()) / d.z(), 0.0, lambda_max);
          box.extend((centre + lambda * d).head<2>());
        }
      }
    }
  }
  // The optical axis at max range too (the range sphere bulges beyond the corner rays).
  box.extend((p_CinN + o_.max_range * R_CtoN.col(2)).head<2>());
  const double pad = 0.5 + c.baseline;
  box.min().array() -= pad;
  box.max().array() += pad;
  return box;
}

StereoFrameObservations ObservationSimulator::observe(int64_t t_us, const TrajectoryState& state,
                                                      const World& world) {
  const StereoCameraOptions& c = camera_.options();
  const Eigen::Matrix3d R_NtoC = c.R_BtoC * state.R_NtoB;
  const Eigen::Matrix3d R_CtoN = R_NtoC.transpose();
  // Left camera centre: p_LinC = R_BtoC (R_NtoB (p_LinN − p_BinN) − p_CinB) = R_NtoC (p_LinN −
  // p_C).
  const Eigen::Vector3d p_CinN = state.p_BinN + state.R_NtoB.transpose() * c.p_CinB;
  const double range2_max = o_.max_range * o_.max_range;

  scratch_.clear();
  world.forEachNear(searchBox(p_CinN, R_CtoN, world), [&](const Landmark& l) {
    const Eigen::Vector3d p_LinC = R_NtoC * (l.p_LinN - p_CinN);
    const double r2 = p_LinC.squaredNorm();
    if (r2 > range2_max || !camera_.isVisible(p_LinC)) return;
    scratch_.push_back({l.id, std::sqrt(r2), p_LinC});
  });
  // Grid order is deterministic; sort by id so that the cap and the noise draws do not depend
  // on the grid layout.
  std::sort(scratch_.begin(), scratch_.end(),
            [](const Candidate& a, const Candidate& b) { return a.id < b.id; });
  if (o_.max_features > 0 && scratch_.size() > static_cast<std::size_t>(o_.max_features)) {
    const auto keep = static_cast<std::size_t>(o_.max_features);
    if (o_.cap == FeatureCap::kNearest) {
      std::stable_sort(scratch_.begin(), scratch_.end(),
                       [](const Candidate& a, const Candidate& b) { return a.range < b.range; });
    } else {
      for (std::size_t i = 0; i < keep; ++i) {
        const std::size_t j = i + static_cast<std::size_t>(rng_.below(scratch_.size() - i));
        std::swap(scratch_[i], scratch_[j]);
      }
    }
    scratch_.resize(keep);
    std::sort(scratch_.begin(), scratch_.end(),
              [](const Candidate& a, const Candidate& b) { return a.id < b.id; });
  }

  StereoFrameObservations frame;
  frame.t_us = t_us;
  frame.observations.reserve(scratch_.size());
  const double max_disparity =
      std::min(c.fx * c.baseline / c.min_depth, static_cast<double>(c.width));
  for (const Candidate& cand : scratch_) {
    StereoObservation obs;
    obs.index = cand.id;
    if (o_.outlier_rate > 0.0 && rng_.uniform() < o_.outlier_rate) {
      const double u = rng_.uniform(0.0, c.width), v = rng_.uniform(0.0, c.height);
      obs.z << u, v, u - rng_.uniform(0.0, max_disparity), v;
    } else {
      obs.z = camera_.project(cand.p_LinC);
      for (int k = 0; k < 4; ++k)
        obs.z(k) += sampleCentredNoise(rng_, o_.kind, o_.shape, o_.sigma_px);
      if (o_.kind == NoiseKind::kNonCentred) obs.z += o_.bias_px;
    }
    frame.observations.push_back(std::move(obs));
  }
  return frame;
}

}  // namespace cvslam::sim
