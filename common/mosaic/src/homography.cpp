#include "cvslam/mosaic/homography.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "cvslam/core/random.h"
#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {
namespace {

constexpr int kMinimalSample = 4;  // four correspondences fix the 8 DOF (§4.3.3.1)

// Hartley normalisation: centroid to the origin, mean distance to √2.
Eigen::Matrix3d normaliser(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  double spread = 0.0;
  for (const auto& p : pts) spread += (p - mean).norm();
  spread /= static_cast<double>(pts.size());
  const double s = spread > 0.0 ? std::sqrt(2.0) / spread : 1.0;
  Eigen::Matrix3d T;
  T << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
  return T;
}

double transferError2(const Eigen::Matrix3d& H, const Eigen::Vector2d& src,
                      const Eigen::Vector2d& dst) {
  return (applyHomography(H, src) - dst).squaredNorm();
}

}  // namespace

Status HomographyOptions::load(const ConfigNode& node) {
  node.get("ransac_threshold_px", ransac_threshold_px);
  node.get("ransac_iterations", ransac_iterations);
  node.get("confidence", confidence);
  node.get("refine_iterations", refine_iterations);
  node.get("min_inliers", min_inliers);
  node.get("seed", seed);
  node.check(ransac_threshold_px > 0.0, "ransac_threshold_px", "must be > 0");
  node.check(ransac_iterations >= 1, "ransac_iterations", "must be ≥ 1");
  node.check(confidence > 0.0 && confidence < 1.0, "confidence", "must be in (0, 1)");
  node.check(refine_iterations >= 0, "refine_iterations", "must be ≥ 0");
  node.check(min_inliers >= kMinimalSample, "min_inliers", "must be ≥ 4");
  return node.status();
}

Eigen::Vector2d applyHomography(const Eigen::Matrix3d& H, const Eigen::Vector2d& x) {
  const Eigen::Vector3d y = H * x.homogeneous();
  return y.hnormalized();
}

Expected<Eigen::Matrix3d> homographyDlt(const std::vector<Eigen::Vector2d>& src,
                                        const std::vector<Eigen::Vector2d>& dst) {
  if (src.size() != dst.size() || src.size() < static_cast<std::size_t>(kMinimalSample))
    return Status::Error("homographyDlt needs ≥ 4 point pairs");
  const Eigen::Matrix3d Ts = normaliser(src), Td = normaliser(dst);
  const auto n = static_cast<Eigen::Index>(src.size());
  // Design matrix of eq. 4.25: two rows per pair (eq. 4.24), h = [h11 h12 h13 h21 … h33].
  Eigen::MatrixXd A(2 * n, 9);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d x = applyHomography(Ts, src[static_cast<std::size_t>(i)]);
    const Eigen::Vector2d xp = applyHomography(Td, dst[static_cast<std::size_t>(i)]);
    A.row(2 * i) << -x.x(), -x.y(), -1, 0, 0, 0, xp.x() * x.x(), xp.x() * x.y(), xp.x();
    A.row(2 * i + 1) << 0, 0, 0, -x.x(), -x.y(), -1, xp.y() * x.x(), xp.y() * x.y(), xp.y();
  }
  // Kernel of A: right singular vector of the smallest singular value. Fewer rows than
  // columns (the minimal sample: 8 × 9) needs the full V.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> h = svd.matrixV().col(8);
  Eigen::Matrix3d Hn;
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d H = Td.inverse() * Hn * Ts;
  if (std::abs(H(2, 2)) < 1e-12 || !H.allFinite())
    return Status::Error("homographyDlt: degenerate configuration");
  return Eigen::Matrix3d(H / H(2, 2));
}

Eigen::Matrix3d refineHomography(const Eigen::Matrix3d& H0, const std::vector<Eigen::Vector2d>& src,
                                 const std::vector<Eigen::Vector2d>& dst, int iterations) {
  using Vector8d = Eigen::Matrix<double, 8, 1>;
  using Matrix8d = Eigen::Matrix<double, 8, 8>;
  // Parameters: the 8 entries of H with H(2,2) = 1 (the scale gauge, eq. 4.22).
  auto toMatrix = [](const Vector8d& p) {
    Eigen::Matrix3d H;
    H << p(0), p(1), p(2), p(3), p(4), p(5), p(6), p(7), 1.0;
    return H;
  };
  Vector8d p;
  const Eigen::Matrix3d Hs = H0 / H0(2, 2);
  p << Hs(0, 0), Hs(0, 1), Hs(0, 2), Hs(1, 0), Hs(1, 1), Hs(1, 2), Hs(2, 0), Hs(2, 1);
  auto cost = [&](const Vector8d& q) {
    const Eigen::Matrix3d H = toMatrix(q);
    double c = 0.0;
    for (std::size_t i = 0; i < src.size(); ++i) c += transferError2(H, src[i], dst[i]);
    return c;
  };
  double lambda = 1e-3;
  double current = cost(p);
  for (int it = 0; it < iterations; ++it) {
    Matrix8d JtJ = Matrix8d::Zero();
    Vector8d Jtr = Vector8d::Zero();
    const Eigen::Matrix3d H = toMatrix(p);
    for (std::size_t i = 0; i < src.size(); ++i) {
      const Eigen::Vector3d y = H * src[i].homogeneous();
      const double w = y.z();
      const Eigen::Vector2d r = y.head<2>() / w - dst[i];
      const double x = src[i].x(), yy = src[i].y();
      Eigen::Matrix<double, 2, 8> J;
      const double u = y.x() / w, v = y.y() / w;
      J << x / w, yy / w, 1 / w, 0, 0, 0, -u * x / w, -u * yy / w,  //
          0, 0, 0, x / w, yy / w, 1 / w, -v * x / w, -v * yy / w;
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Matrix8d A = JtJ;
      A.diagonal() *= (1.0 + lambda);
      const Vector8d step = A.ldlt().solve(-Jtr);
      const Vector8d q = p + step;
      const double c = cost(q);
      if (std::isfinite(c) && c < current) {
        p = q;
        improved = current - c > 1e-12 * current;
        current = c;
        lambda *= 0.3;
        if (!improved) return toMatrix(p);  // converged
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  return toMatrix(p);
}

Expected<HomographyEstimate> estimateHomography(const std::vector<Eigen::Vector2d>& src,
                                                const std::vector<Eigen::Vector2d>& dst,
                                                const HomographyOptions& o) {
  const std::size_t n = src.size();
  if (n != dst.size()) return Status::Error("estimateHomography: src and dst sizes differ");
  if (n < static_cast<std::size_t>(std::max(kMinimalSample, o.min_inliers)))
    return Status::Error("estimateHomography: " + std::to_string(n) + " matches, need " +
                         std::to_string(std::max(kMinimalSample, o.min_inliers)));
  const double thr2 = o.ransac_threshold_px * o.ransac_threshold_px;
  uint64_t state = o.seed;
  std::vector<bool> best;
  int best_count = 0;
  double needed = o.ransac_iterations;
  std::vector<Eigen::Vector2d> s4(kMinimalSample), d4(kMinimalSample);
  for (int it = 0; it < o.ransac_iterations && it < needed; ++it) {
    std::size_t idx[kMinimalSample];
    for (int k = 0; k < kMinimalSample; ++k) {
      bool fresh = false;
      while (!fresh) {
        idx[k] = static_cast<std::size_t>(splitmix64(state) % n);
        fresh = std::find(idx, idx + k, idx[k]) == idx + k;
      }
      s4[static_cast<std::size_t>(k)] = src[idx[k]];
      d4[static_cast<std::size_t>(k)] = dst[idx[k]];
    }
    const auto H = homographyDlt(s4, d4);
    if (!H.ok()) continue;
    std::vector<bool> in(n);
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      in[i] = transferError2(*H, src[i], dst[i]) < thr2;
      count += in[i];
    }
    if (count > best_count) {
      best_count = count;
      best = std::move(in);
      // Samples needed to draw one all-inlier sample with the requested confidence.
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double p_good = std::pow(w, kMinimalSample);
      if (p_good >= 1.0) break;
      needed = std::log(1.0 - o.confidence) / std::log(1.0 - p_good);
    }
  }
  if (best_count < o.min_inliers)
    return Status::Error("estimateHomography: " + std::to_string(best_count) +
                         " RANSAC inliers, need " + std::to_string(o.min_inliers));
  HomographyEstimate e;
  // Fit on the inliers, refine, and re-classify once with the refined H.
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector2d> si, di;
    for (std::size_t i = 0; i < n; ++i)
      if (best[i]) {
        si.push_back(src[i]);
        di.push_back(dst[i]);
      }
    const auto H = homographyDlt(si, di);
    if (!H.ok()) return H.status();
    e.H = refineHomography(*H, si, di, o.refine_iterations);
    for (std::size_t i = 0; i < n; ++i) best[i] = transferError2(e.H, src[i], dst[i]) < thr2;
  }
  e.inliers = best;
  double sum2 = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (best[i]) {
      ++e.inlier_count;
      sum2 += transferError2(e.H, src[i], dst[i]);
    }
  if (e.inlier_count < o.min_inliers)
    return Status::Error("estimateHomography: too few inliers after refinement");
  e.rms_px = std::sqrt(sum2 / e.inlier_count);
  return e;
}

}  // namespace cvslam::mosaic
