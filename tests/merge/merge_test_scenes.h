#pragma once
// Synthetic correspondences for the frame-relation tests: landmarks seen by two agents whose
// frames differ by a known 4-dof relation, each landmark estimated with a stereo-like
// covariance (long along the line of sight), optionally with an error common to all of one
// agent's landmarks (its vehicle's) and with wrong matches.

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cmath>
#include <vector>

#include "cvslam/core/random.h"
#include "cvslam/merge/four_dof_aligner.h"
#include "cvslam/merge/frame_relation.h"

namespace cvslam::merge::scenes {

struct Scene {
  FrameRelation truth;  ///< B → A
  AlignmentPoints points;
  std::vector<bool> outlier;
};

struct SceneOptions {
  int landmarks = 40;
  double outlier_fraction = 0.0;
  double box = 20.0;          ///< landmarks spread over box × box × box/5 [m]
  double common_sigma = 0.0;  ///< σ of an error shared by all of A's landmarks [m]
};

inline Eigen::Vector3d gaussian3(Rng& rng) {
  return Eigen::Vector3d(rng.gaussian(), rng.gaussian(), rng.gaussian());
}

/// A stereo-like covariance: σ_depth along a random line of sight, σ_perp across it.
inline Eigen::Matrix3d stereoCovariance(Rng& rng) {
  const Eigen::Vector3d dir = gaussian3(rng).normalized();
  const double perp = rng.uniform(0.02, 0.08);
  const double depth = rng.uniform(0.08, 0.4);
  return perp * perp * Eigen::Matrix3d::Identity() +
         (depth * depth - perp * perp) * dir * dir.transpose();
}

inline Eigen::Vector3d draw(Rng& rng, const Eigen::Matrix3d& C) {
  const Eigen::LLT<Eigen::Matrix3d> llt(C);
  return llt.matrixL() * gaussian3(rng);
}

inline Scene makeScene(Rng& rng, const SceneOptions& o) {
  Scene s;
  s.truth.x << rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(-1, 1),
      rng.uniform(-M_PI, M_PI);
  const Eigen::Matrix3d R = s.truth.rotation();
  const auto n = static_cast<std::size_t>(o.landmarks);
  std::vector<Eigen::Matrix3d> Ca(n), Cb(n);
  const Eigen::Vector3d common = o.common_sigma * gaussian3(rng);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d p_A(rng.uniform(-o.box / 2, o.box / 2),
                              rng.uniform(-o.box / 2, o.box / 2),
                              rng.uniform(-o.box / 10, o.box / 10));
    const Eigen::Vector3d p_B = R.transpose() * (p_A - s.truth.translation());
    Ca[k] = stereoCovariance(rng);
    Cb[k] = stereoCovariance(rng);
    const bool wrong = rng.uniform() < o.outlier_fraction;
    s.outlier.push_back(wrong);
    s.points.a.push_back(p_A + draw(rng, Ca[k]) + common);
    // A wrong match: some other place of B's map.
    s.points.b.push_back(wrong ? Eigen::Vector3d(rng.uniform(-o.box, o.box),
                                                 rng.uniform(-o.box, o.box), rng.uniform(-2, 2))
                               : p_B + draw(rng, Cb[k]));
  }
  s.points.cov_a = blockDiagonal(Ca);
  s.points.cov_b = blockDiagonal(Cb);
  if (o.common_sigma > 0.0) {
    for (std::size_t u = 0; u < n; ++u)
      for (std::size_t v = 0; v < n; ++v)
        s.points.cov_a.block<3, 3>(static_cast<Eigen::Index>(3 * u),
                                   static_cast<Eigen::Index>(3 * v)) +=
            o.common_sigma * o.common_sigma * Eigen::Matrix3d::Identity();
  }
  return s;
}

inline double relationNees(const FrameRelation& estimate, const FrameRelation& truth) {
  const FrameRelation::Vector4d e = relationDifference(estimate.x, truth.x);
  return e.dot(estimate.P.ldlt().solve(e));
}

}  // namespace cvslam::merge::scenes
