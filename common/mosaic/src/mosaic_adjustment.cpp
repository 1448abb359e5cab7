#include "cvslam/mosaic/mosaic_adjustment.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <map>
#include <utility>

#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {
namespace {

constexpr int kDof = 8;  // a homography correction: 3×3 with the (2,2) entry fixed
using Vector8d = Eigen::Matrix<double, kDof, 1>;
using Matrix28d = Eigen::Matrix<double, 2, kDof>;
using Basis = Eigen::Matrix<double, kDof, Eigen::Dynamic>;

// Δ = B θ: the model's parameters θ in the 8 homography entries (row-major, Δ22 = 0).
Basis basis(CorrectionModel model) {
  switch (model) {
    case CorrectionModel::kSimilarity: {
      // [[a −b tx] [b a ty] [0 0]]: shift, rotation and scale (pose errors over a plane).
      Basis B = Basis::Zero(kDof, 4);
      B(0, 0) = B(4, 0) = 1.0;
      B(1, 1) = -1.0;
      B(3, 1) = 1.0;
      B(2, 2) = 1.0;
      B(5, 3) = 1.0;
      return B;
    }
    case CorrectionModel::kAffine: {
      Basis B = Basis::Zero(kDof, 6);
      for (int i = 0; i < 6; ++i) B(i, i) = 1.0;
      return B;
    }
    case CorrectionModel::kHomography:
      break;
  }
  return Basis::Identity(kDof, kDof);
}

// The correction of a frame in its normalised footprint coordinates q = (g − c)/s:
// p = c + s·π((I + Δ)[q; 1]), Δ = the 8 parameters (row-major, Δ22 = 0).
struct Frame {
  Eigen::Vector2d c;
  double s = 1.0;
  Vector8d delta = Vector8d::Zero();

  Eigen::Matrix3d correction() const {
    Eigen::Matrix3d D;
    D << delta(0), delta(1), delta(2), delta(3), delta(4), delta(5), delta(6), delta(7), 0.0;
    return Eigen::Matrix3d::Identity() + D;
  }
  // p(g) and its Jacobian with respect to δ.
  Eigen::Vector2d apply(const Eigen::Vector2d& g, Matrix28d* J) const {
    const Eigen::Vector2d q = (g - c) / s;
    const Eigen::Vector3d y = correction() * q.homogeneous();
    const double w = y.z(), u = y.x() / w, v = y.y() / w;
    *J << q.x() / w, q.y() / w, 1 / w, 0, 0, 0, -u * q.x() / w, -u * q.y() / w,  //
        0, 0, 0, q.x() / w, q.y() / w, 1 / w, -v * q.x() / w, -v * q.y() / w;
    *J *= s;
    return c + s * Eigen::Vector2d(u, v);
  }
};

}  // namespace

Status AdjustmentOptions::load(const ConfigNode& node) {
  node.get("sigma_match_px", sigma_match_px);
  node.get("sigma_cross_px", sigma_cross_px);
  node.get("sigma_smooth_px", sigma_smooth_px);
  node.get("sigma_shift_px", sigma_shift_px);
  node.get("sigma_shape_px", sigma_shape_px);
  node.get("iterations", iterations);
  node.getEnum("model", model,
               {{"similarity", CorrectionModel::kSimilarity},
                {"affine", CorrectionModel::kAffine},
                {"homography", CorrectionModel::kHomography}});
  node.check(sigma_match_px > 0.0, "sigma_match_px", "must be > 0");
  node.check(sigma_cross_px > 0.0, "sigma_cross_px", "must be > 0");
  node.check(sigma_smooth_px > 0.0, "sigma_smooth_px", "must be > 0");
  node.check(sigma_shift_px > 0.0, "sigma_shift_px", "must be > 0");
  node.check(sigma_shape_px > 0.0, "sigma_shape_px", "must be > 0");
  node.check(iterations >= 1, "iterations", "must be ≥ 1");
  return node.status();
}

Expected<std::vector<Eigen::Matrix3d>> adjustFrames(const std::vector<FramePrior>& priors,
                                                    const std::vector<FrameLink>& links,
                                                    const AdjustmentOptions& o) {
  const int n = static_cast<int>(priors.size());
  if (n == 0) return std::vector<Eigen::Matrix3d>{};
  std::vector<Frame> frames(priors.size());
  for (std::size_t k = 0; k < priors.size(); ++k) {
    frames[k].c = priors[k].centre;
    double s = 0.0;
    for (const Eigen::Vector2d& g : priors[k].corners)
      s = std::max(s, (g - priors[k].centre).norm());
    frames[k].s = s > 0.0 ? s : 1.0;
  }
  const Basis B = basis(o.model);
  const auto d = static_cast<int>(B.cols());
  const double w_shift = 1.0 / (o.sigma_shift_px * o.sigma_shift_px);
  const double w_shape = 1.0 / (o.sigma_shape_px * o.sigma_shape_px);
  const double w_own = 1.0 / (o.sigma_match_px * o.sigma_match_px);
  const double w_cross = 1.0 / (o.sigma_cross_px * o.sigma_cross_px);
  const double w_smooth = 1.0 / (o.sigma_smooth_px * o.sigma_smooth_px);
  for (int it = 0; it < o.iterations; ++it) {
    // Gauss–Newton normal equations, accumulated in dense 8×8 blocks per frame pair.
    std::map<std::pair<int, int>, Eigen::MatrixXd> blocks;
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n * d);
    auto block = [&](int i, int j) -> Eigen::MatrixXd& {
      auto [pos, fresh] = blocks.try_emplace({i, j}, Eigen::MatrixXd::Zero(d, d));
      (void)fresh;
      return pos->second;
    };
    for (int k = 0; k < n; ++k) {
      const Frame& f = frames[static_cast<std::size_t>(k)];
      Eigen::MatrixXd& A = block(k, k);
      // The prior: no shift of the footprint centre, and no change of the corners relative
      // to it (rotation, scale, shear), each with its own σ.
      Matrix28d Jc8;
      const Eigen::Vector2d c = priors[static_cast<std::size_t>(k)].centre;
      const Eigen::Vector2d rc = f.apply(c, &Jc8) - c;
      const Eigen::MatrixXd Jc = Jc8 * B;
      A += w_shift * Jc.transpose() * Jc;
      b.segment(k * d, d) -= w_shift * Jc.transpose() * rc;
      for (const Eigen::Vector2d& g : priors[static_cast<std::size_t>(k)].corners) {
        Matrix28d J8;
        const Eigen::Vector2d r = f.apply(g, &J8) - g - rc;
        const Eigen::MatrixXd J = J8 * B - Jc;
        A += w_shape * J.transpose() * J;
        b.segment(k * d, d) -= w_shape * J.transpose() * r;
      }
    }
    for (const FrameLink& l : links) {
      Matrix28d Ji8, Jj8;
      const Eigen::Vector2d r = frames[static_cast<std::size_t>(l.i)].apply(l.g_i, &Ji8) -
                                frames[static_cast<std::size_t>(l.j)].apply(l.g_j, &Jj8);
      const Eigen::MatrixXd Ji = Ji8 * B, Jj = Jj8 * B;
      const double wm =
          l.kind == FrameLink::kCross ? w_cross : (l.kind == FrameLink::kSmooth ? w_smooth : w_own);
      block(l.i, l.i) += wm * Ji.transpose() * Ji;
      block(l.j, l.j) += wm * Jj.transpose() * Jj;
      block(l.i, l.j) -= wm * Ji.transpose() * Jj;
      block(l.j, l.i) -= wm * Jj.transpose() * Ji;
      b.segment(l.i * d, d) -= wm * Ji.transpose() * r;
      b.segment(l.j * d, d) += wm * Jj.transpose() * r;
    }
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(blocks.size() * static_cast<std::size_t>(d * d));
    for (const auto& [ij, M] : blocks)
      for (int r = 0; r < d; ++r)
        for (int c = 0; c < d; ++c)
          triplets.emplace_back(ij.first * d + r, ij.second * d + c, M(r, c));
    Eigen::SparseMatrix<double> N(n * d, n * d);
    N.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(N);
    if (solver.info() != Eigen::Success) return Status::Error("mosaic adjustment: singular system");
    const Eigen::VectorXd step = solver.solve(b);
    if (solver.info() != Eigen::Success || !step.allFinite())
      return Status::Error("mosaic adjustment: solve failed");
    for (int k = 0; k < n; ++k)
      frames[static_cast<std::size_t>(k)].delta += B * step.segment(k * d, d);
  }
  std::vector<Eigen::Matrix3d> out;
  out.reserve(frames.size());
  for (const Frame& f : frames) {
    // p = c + s·π(C·[(g − c)/s; 1]) as one 3×3 matrix acting on [g; 1].
    Eigen::Matrix3d to_q, from_q;
    to_q << 1 / f.s, 0, -f.c.x() / f.s, 0, 1 / f.s, -f.c.y() / f.s, 0, 0, 1;
    from_q << f.s, 0, f.c.x(), 0, f.s, f.c.y(), 0, 0, 1;
    out.push_back(from_q * f.correction() * to_q);
  }
  return out;
}

}  // namespace cvslam::mosaic
