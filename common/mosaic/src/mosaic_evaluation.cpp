#include "cvslam/mosaic/mosaic_evaluation.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>

namespace cvslam::mosaic {
namespace {

constexpr double kP90 = 0.9;

// Least-squares 2-D similarity b ≈ s·R·a + t (Umeyama in 2-D): with points as complex
// numbers, centred, s·e^{iθ} = Σ conj(a_i) b_i / Σ |a_i|².
Eigen::Matrix3d fitSimilarity(const std::vector<Eigen::Vector2d>& a,
                              const std::vector<Eigen::Vector2d>& b) {
  Eigen::Vector2d ma = Eigen::Vector2d::Zero(), mb = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(a.size());
  mb /= static_cast<double>(b.size());
  std::complex<double> num = 0.0;
  double den = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::complex<double> za(a[i].x() - ma.x(), a[i].y() - ma.y());
    const std::complex<double> zb(b[i].x() - mb.x(), b[i].y() - mb.y());
    num += std::conj(za) * zb;
    den += std::norm(za);
  }
  const std::complex<double> q = den > 0.0 ? num / den : 1.0;
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S << q.real(), -q.imag(), 0, q.imag(), q.real(), 0, 0, 0, 1;
  S.topRightCorner<2, 1>() = mb - S.topLeftCorner<2, 2>() * ma;
  return S;
}

}  // namespace

ErrorStats errorStats(std::vector<double> e) {
  ErrorStats s;
  s.count = static_cast<int>(e.size());
  if (e.empty()) return s;
  std::sort(e.begin(), e.end());
  const std::size_t n = e.size();
  s.median = n % 2 ? e[n / 2] : 0.5 * (e[n / 2 - 1] + e[n / 2]);
  s.mean = std::accumulate(e.begin(), e.end(), 0.0) / static_cast<double>(n);
  s.p90 = e[std::min(n - 1, static_cast<std::size_t>(kP90 * static_cast<double>(n)))];
  s.max = e.back();
  return s;
}

RegistrationError registrationError(const MosaicGrid& grid,
                                    const std::vector<PlacedTruth>& frames) {
  std::vector<Eigen::Vector2d> placed, truth;
  for (const PlacedTruth& f : frames)
    for (const TruthPoint& t : f.points) {
      placed.push_back(applyHomography(f.H, t.pixel));
      truth.push_back(grid.toPixel(t.ground_xy));
    }
  RegistrationError r;
  std::vector<double> raw(placed.size()), aligned(placed.size());
  for (std::size_t i = 0; i < placed.size(); ++i) raw[i] = (placed[i] - truth[i]).norm();
  r.raw = errorStats(raw);
  if (placed.size() >= 2) {
    r.similarity = fitSimilarity(placed, truth);
    for (std::size_t i = 0; i < placed.size(); ++i)
      aligned[i] = (applyHomography(r.similarity, placed[i]) - truth[i]).norm();
    r.aligned = errorStats(aligned);
  }
  return r;
}

cv::Mat sampleTruth(const MosaicGrid& grid, const Eigen::Vector2d& origin, cv::Size size, int scale,
                    const std::function<double(double x, double y)>& value) {
  cv::Mat out(size, CV_32F);
  for (int r = 0; r < size.height; ++r)
    for (int c = 0; c < size.width; ++c) {
      const Eigen::Vector2d px = origin + Eigen::Vector2d(c, r) / scale;
      const Eigen::Vector2d xy = grid.toGround(px);
      out.at<float>(r, c) = static_cast<float>(value(xy.x(), xy.y()));
    }
  return out;
}

}  // namespace cvslam::mosaic
