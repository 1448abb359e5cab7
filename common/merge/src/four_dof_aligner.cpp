#include "cvslam/merge/four_dof_aligner.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <string>

#include "cvslam/core/random.h"
#include "cvslam/filter/chi_square.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"

namespace cvslam::merge {

namespace {

using Vector4d = FrameRelation::Vector4d;
using Matrix4d = FrameRelation::Matrix4d;

Status validate(const AlignmentPoints& p) {
  const std::size_t n = p.a.size();
  if (p.b.size() != n) return Status::Error("alignment: a and b differ in length");
  const Eigen::Index m = static_cast<Eigen::Index>(3 * n);
  if (p.cov_a.rows() != m || p.cov_a.cols() != m || p.cov_b.rows() != m || p.cov_b.cols() != m)
    return Status::Error("alignment: covariances must be " + std::to_string(m) + "×" +
                         std::to_string(m));
  for (std::size_t k = 0; k < n; ++k)
    if (!p.a[k].allFinite() || !p.b[k].allFinite())
      return Status::Error("alignment: non-finite point " + std::to_string(k));
  if (!p.cov_a.allFinite() || !p.cov_b.allFinite())
    return Status::Error("alignment: non-finite covariance");
  return Status::Ok();
}

// Squared Mahalanobis residual of correspondence k under relation x (its own 3×3 blocks).
double pointNis(const AlignmentPoints& p, std::size_t k, const FrameRelation& rel) {
  const Eigen::Index i = static_cast<Eigen::Index>(3 * k);
  const Eigen::Matrix3d R = rel.rotation();
  const Eigen::Matrix3d S =
      p.cov_a.block<3, 3>(i, i) + R * p.cov_b.block<3, 3>(i, i) * R.transpose();
  const Eigen::Vector3d r = p.a[k] - rel.apply(p.b[k]);
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(S);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return INFINITY;
  return r.dot(ldlt.solve(r));
}

std::vector<int> gate(const AlignmentPoints& p, const FrameRelation& rel, double threshold,
                      double* cost) {
  std::vector<int> inliers;
  *cost = 0.0;
  for (std::size_t k = 0; k < p.a.size(); ++k) {
    const double d2 = pointNis(p, k, rel);
    if (d2 <= threshold) {
      inliers.push_back(static_cast<int>(k));
      *cost += d2;
    }
  }
  return inliers;
}

// The two-point minimal solution: yaw from the horizontal direction between the points in
// each frame, translation from their mean.
bool minimalSolution(const AlignmentPoints& p, std::size_t i, std::size_t j, double separation,
                     FrameRelation* rel) {
  const Eigen::Vector3d da = p.a[j] - p.a[i];
  const Eigen::Vector3d db = p.b[j] - p.b[i];
  if (da.head<2>().norm() < separation || db.head<2>().norm() < separation) return false;
  rel->x(3) = wrapAngle(std::atan2(da(1), da(0)) - std::atan2(db(1), db(0)));
  const Eigen::Matrix3d R = rel->rotation();
  rel->x.head<3>() = 0.5 * (p.a[i] + p.a[j] - R * (p.b[i] + p.b[j]));
  return true;
}

struct Solve {
  FrameRelation relation;
  double cost = 0.0;  // rᵀ S⁻¹ r
  bool ok = false;
};

// Gauss–Newton on Σ rᵀ S⁻¹ r over `inliers` with the joint covariance S = C_A + B C_B Bᵀ
// (B = diag(R, …, R), re-evaluated at each step).
Solve refine(const AlignmentPoints& p, const std::vector<int>& inliers, FrameRelation start,
             int iterations) {
  const Eigen::Index m = static_cast<Eigen::Index>(3 * inliers.size());
  Eigen::MatrixXd Ca(m, m), Cb(m, m);
  for (std::size_t u = 0; u < inliers.size(); ++u) {
    for (std::size_t v = 0; v < inliers.size(); ++v) {
      const Eigen::Index iu = 3 * inliers[u], iv = 3 * inliers[v];
      const Eigen::Index ou = static_cast<Eigen::Index>(3 * u),
                         ov = static_cast<Eigen::Index>(3 * v);
      Ca.block<3, 3>(ou, ov) = p.cov_a.block<3, 3>(iu, iv);
      Cb.block<3, 3>(ou, ov) = p.cov_b.block<3, 3>(iu, iv);
    }
  }
  Solve s;
  s.relation = start;
  Eigen::VectorXd r(m);
  Eigen::MatrixXd J(m, 4);
  Eigen::MatrixXd S(m, m);
  for (int it = 0; it <= iterations; ++it) {
    const Eigen::Matrix3d R = s.relation.rotation();
    for (std::size_t u = 0; u < inliers.size(); ++u) {
      FrameRelation::Matrix34d J_x;
      const std::size_t k = static_cast<std::size_t>(inliers[u]);
      const Eigen::Index o = static_cast<Eigen::Index>(3 * u);
      r.segment<3>(o) = p.a[k] - s.relation.apply(p.b[k], &J_x);
      J.middleRows<3>(o) = -J_x;
    }
    for (std::size_t u = 0; u < inliers.size(); ++u)
      for (std::size_t v = 0; v < inliers.size(); ++v) {
        const Eigen::Index ou = static_cast<Eigen::Index>(3 * u),
                           ov = static_cast<Eigen::Index>(3 * v);
        S.block<3, 3>(ou, ov) = Ca.block<3, 3>(ou, ov) + R * Cb.block<3, 3>(ou, ov) * R.transpose();
      }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return s;
    const Eigen::MatrixXd WJ = ldlt.solve(J);
    const Matrix4d H = J.transpose() * WJ;
    const Eigen::FullPivLU<Matrix4d> lu(H);
    if (!lu.isInvertible()) return s;
    s.relation.P = lu.inverse();
    s.cost = r.dot(ldlt.solve(r));
    s.ok = true;
    if (it == iterations) break;
    const Vector4d delta = -s.relation.P * (WJ.transpose() * r);
    s.relation.x += delta;
    s.relation.x(3) = wrapAngle(s.relation.x(3));
    if (delta.head<3>().norm() < 1e-9 && std::abs(delta(3)) < 1e-10) {
      iterations = it + 1;  // one more pass evaluates P and the cost at the solution
    }
  }
  return s;
}

double horizontalSpread(const AlignmentPoints& p, const std::vector<int>& inliers) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int k : inliers) mean += p.a[static_cast<std::size_t>(k)].head<2>();
  mean /= static_cast<double>(inliers.size());
  double sum = 0.0;
  for (int k : inliers) sum += (p.a[static_cast<std::size_t>(k)].head<2>() - mean).squaredNorm();
  return std::sqrt(sum / static_cast<double>(inliers.size()));
}

}  // namespace

Eigen::MatrixXd blockDiagonal(const std::vector<Eigen::Matrix3d>& blocks) {
  const Eigen::Index m = static_cast<Eigen::Index>(3 * blocks.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(m, m);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Eigen::Index o = static_cast<Eigen::Index>(3 * k);
    out.block<3, 3>(o, o) = blocks[k];
  }
  return out;
}

Status FourDofAlignerOptions::load(const ConfigNode& node) {
  node.get("ransac_iterations", ransac_iterations);
  node.get("inlier_probability", inlier_probability);
  node.get("min_inliers", min_inliers);
  node.get("min_pair_separation", min_pair_separation);
  node.get("min_inlier_spread", min_inlier_spread);
  node.get("refine_iterations", refine_iterations);
  node.get("regate_rounds", regate_rounds);
  int64_t seed_value = static_cast<int64_t>(seed);
  node.get("seed", seed_value);
  node.check(ransac_iterations >= 1, "ransac_iterations", "must be >= 1");
  node.check(inlier_probability > 0.0 && inlier_probability < 1.0, "inlier_probability",
             "must be in (0, 1)");
  node.check(min_inliers >= 3, "min_inliers", "must be >= 3 (4 unknowns)");
  node.check(min_pair_separation > 0.0, "min_pair_separation", "must be > 0 m");
  node.check(min_inlier_spread >= 0.0, "min_inlier_spread", "must be >= 0 m");
  node.check(refine_iterations >= 1, "refine_iterations", "must be >= 1");
  node.check(regate_rounds >= 0, "regate_rounds", "must be >= 0");
  node.check(seed_value >= 0, "seed", "must be >= 0");
  seed = static_cast<uint64_t>(seed_value);
  return node.status();
}

FourDofAligner::FourDofAligner(const FourDofAlignerOptions& options)
    : o_(options), gate_(chiSquareQuantile(options.inlier_probability, 3)) {}

Expected<FourDofAlignment> FourDofAligner::align(const AlignmentPoints& points) const {
  if (Status s = validate(points); !s.ok()) return s;
  const std::size_t n = points.a.size();
  if (n < static_cast<std::size_t>(o_.min_inliers))
    return Status::Error("alignment: " + std::to_string(n) + " correspondences, need " +
                         std::to_string(o_.min_inliers));
  // 1. RANSAC over two-point samples: most inliers, then the lowest cost.
  Rng rng(o_.seed);
  FrameRelation best;
  std::vector<int> best_inliers;
  double best_cost = INFINITY;
  for (int it = 0; it < o_.ransac_iterations; ++it) {
    const auto i = static_cast<std::size_t>(rng.uniform() * static_cast<double>(n));
    const auto j = static_cast<std::size_t>(rng.uniform() * static_cast<double>(n));
    FrameRelation hypothesis;
    if (i == j || !minimalSolution(points, i, j, o_.min_pair_separation, &hypothesis)) continue;
    double cost = 0.0;
    std::vector<int> inliers = gate(points, hypothesis, gate_, &cost);
    if (inliers.size() > best_inliers.size() ||
        (inliers.size() == best_inliers.size() && cost < best_cost)) {
      best = hypothesis;
      best_inliers = std::move(inliers);
      best_cost = cost;
    }
  }
  FourDofAlignment out;
  out.hypothesis_inliers = static_cast<int>(best_inliers.size());
  if (best_inliers.size() < static_cast<std::size_t>(o_.min_inliers))
    return Status::Error("alignment: best hypothesis has " + std::to_string(best_inliers.size()) +
                         " inliers of " + std::to_string(n) + ", need " +
                         std::to_string(o_.min_inliers));
  // 2. Generalised least squares on the inliers, re-gated until the set settles.
  Solve solve;
  std::vector<int> inliers = best_inliers;
  for (int round = 0;; ++round) {
    solve = refine(points, inliers, round == 0 ? best : solve.relation, o_.refine_iterations);
    if (!solve.ok) return Status::Error("alignment: the inliers' covariance is singular");
    double cost = 0.0;
    std::vector<int> regated = gate(points, solve.relation, gate_, &cost);
    if (regated == inliers || round == o_.regate_rounds) break;
    inliers = std::move(regated);
    if (inliers.size() < static_cast<std::size_t>(o_.min_inliers)) break;
  }
  if (inliers.size() < static_cast<std::size_t>(o_.min_inliers))
    return Status::Error("alignment: " + std::to_string(inliers.size()) +
                         " inliers after refinement, need " + std::to_string(o_.min_inliers));
  const double spread = horizontalSpread(points, inliers);
  if (spread < o_.min_inlier_spread)
    return Status::Error("alignment: inliers spread over " + std::to_string(spread) + " m, need " +
                         std::to_string(o_.min_inlier_spread) + " m");
  out.relation = solve.relation;
  out.inliers = std::move(inliers);
  out.inlier_nis = solve.cost / std::max(1.0, 3.0 * static_cast<double>(out.inliers.size()) - 4.0);
  return out;
}

}  // namespace cvslam::merge
