#include "cvslam/mosaic/mosaic_evaluation.h"

#include "cvslam/io/config_node.h"

#include <Eigen/LU>
#include <opencv2/imgproc.hpp>

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
                    const std::function<double(double x, double y)>& value,
                    const Eigen::Matrix3d& mosaic_to_true) {
  cv::Mat out(size, CV_32F);
  for (int r = 0; r < size.height; ++r)
    for (int c = 0; c < size.width; ++c) {
      const Eigen::Vector2d px = origin + Eigen::Vector2d(c, r) / scale;
      const Eigen::Vector2d xy = grid.toGround(applyHomography(mosaic_to_true, px));
      out.at<float>(r, c) = static_cast<float>(value(xy.x(), xy.y()));
    }
  return out;
}

Status EvaluationOptions::load(const ConfigNode& node) {
  node.get("frame_period", frame_period);
  node.get("truth_grid", truth_grid);
  node.get("sr_patches", sr_patches);
  node.get("sr_patch_px", sr_patch_px);
  node.get("sr_border_px", sr_border_px);
  node.get("sr_min_frames", sr_min_frames);
  node.check(frame_period >= 0.0, "frame_period", "must be ≥ 0");
  node.check(truth_grid >= 2, "truth_grid", "must be ≥ 2");
  node.check(sr_patches >= 0, "sr_patches", "must be ≥ 0");
  node.check(sr_patch_px >= 8, "sr_patch_px", "must be ≥ 8");
  node.check(sr_border_px >= 0 && 2 * sr_border_px < sr_patch_px, "sr_border_px",
             "must be in [0, sr_patch_px / 2)");
  node.check(sr_min_frames >= 1, "sr_min_frames", "must be ≥ 1");
  return node.status();
}

Expected<SuperResolutionPatch> evaluateSuperResolution(
    const MosaicBuilder& builder, const std::vector<FramePlacement>& placements,
    const Eigen::Vector2d& origin, const SuperResolutionOptions& sr, const EvaluationOptions& o,
    const std::function<double(double x, double y)>& truth, const Eigen::Matrix3d& mosaic_to_true) {
  const int n = o.sr_patch_px, s = sr.scale;
  const cv::Size hr(n * s, n * s);
  // Mosaic pixel m ↔ fine-grid pixel (m − origin)·scale.
  Eigen::Matrix3d to_hr = Eigen::Matrix3d::Identity();
  to_hr.topLeftCorner<2, 2>() *= s;
  to_hr.topRightCorner<2, 1>() = -s * origin;
  SuperResolutionPatch p;
  p.origin = origin;
  std::vector<LowResFrame> lr;
  const std::vector<MosaicFrame>& frames = builder.frames();
  for (std::size_t k = 0; k < frames.size() && k < placements.size(); ++k) {
    const Eigen::Matrix3d Hinv = placements[k].H.inverse();
    bool inside = true;
    for (int cy = 0; cy <= 1 && inside; ++cy)
      for (int cx = 0; cx <= 1 && inside; ++cx) {
        const Eigen::Vector2d u = applyHomography(Hinv, origin + Eigen::Vector2d(cx, cy) * n);
        inside = u.x() >= 0 && u.y() >= 0 && u.x() <= frames[k].image.cols - 1 &&
                 u.y() <= frames[k].image.rows - 1;
      }
    if (!inside) continue;
    LowResFrame f;
    frames[k].image.convertTo(f.image, CV_32F, placements[k].photometric.gain,
                              placements[k].photometric.bias);
    f.H_to_hr = to_hr * placements[k].H;
    lr.push_back(f);
  }
  p.frames = static_cast<int>(lr.size());
  if (p.frames < o.sr_min_frames)
    return Status::Error("super-resolution patch seen by " + std::to_string(p.frames) + " frames");
  // The plain mosaic on the fine grid: bicubic from the mosaic pixels.
  cv::Mat mosaic;
  builder.image().convertTo(mosaic, CV_32F);
  const cv::Matx23d hr_to_mosaic(1.0 / s, 0, origin.x(), 0, 1.0 / s, origin.y());
  cv::warpAffine(mosaic, p.plain, hr_to_mosaic, hr, cv::INTER_CUBIC | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  auto x = papoulisGerchberg(lr, hr, sr, p.plain);
  if (!x.ok()) return x.status();
  p.sr = *x;
  p.truth = sampleTruth(builder.grid(), origin, hr, s, truth, mosaic_to_true);
  const int b = o.sr_border_px * s;
  const cv::Rect inner(b, b, hr.width - 2 * b, hr.height - 2 * b);
  p.psnr_plain_db = psnr(p.plain(inner), p.truth(inner));
  p.psnr_sr_db = psnr(p.sr(inner), p.truth(inner));
  return p;
}

}  // namespace cvslam::mosaic
