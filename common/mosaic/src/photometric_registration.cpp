#include "cvslam/mosaic/photometric_registration.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <vector>

#include "cvslam/io/config_node.h"

namespace cvslam::mosaic {
namespace {

// Orthogonal regression (total least squares) of b on a over pairs with keep[i].
Expected<GainBias> fitLine(const std::vector<float>& a, const std::vector<float>& b,
                           const std::vector<bool>& keep) {
  double n = 0, ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (keep[i]) {
      ++n;
      ma += a[i];
      mb += b[i];
    }
  if (n < 2) return Status::Error("photometric registration: no overlapping pixels");
  ma /= n;
  mb /= n;
  Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i)
    if (keep[i]) {
      const Eigen::Vector2d d(a[i] - ma, b[i] - mb);
      C += d * d.transpose();
    }
  // Principal axis of the scatter = direction of the fitted line.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(C);
  const Eigen::Vector2d dir = eig.eigenvectors().col(1);
  if (std::abs(dir.x()) < 1e-9) return Status::Error("photometric registration: flat image");
  GainBias g;
  g.gain = dir.y() / dir.x();
  g.bias = mb - g.gain * ma;
  g.pixels = static_cast<int>(n);
  return g;
}

}  // namespace

Status PhotometricOptions::load(const ConfigNode& node) {
  node.get("enabled", enabled);
  node.get("min_pixels", min_pixels);
  node.get("outlier_sigma", outlier_sigma);
  node.get("max_gain_change", max_gain_change);
  node.get("smoothing_px", smoothing_px);
  node.check(smoothing_px >= 0.0, "smoothing_px", "must be ≥ 0");
  node.check(min_pixels >= 2, "min_pixels", "must be ≥ 2");
  node.check(outlier_sigma > 0.0, "outlier_sigma", "must be > 0");
  node.check(max_gain_change > 0.0, "max_gain_change", "must be > 0");
  return node.status();
}

Expected<GainBias> estimateGainBias(const cv::Mat& image, const cv::Mat& reference,
                                    const cv::Mat& mask, const PhotometricOptions& o) {
  if (image.size() != reference.size() || (!mask.empty() && mask.size() != image.size()))
    return Status::Error("photometric registration: image sizes differ");
  cv::Mat a, b;
  image.convertTo(a, CV_32F);
  reference.convertTo(b, CV_32F);
  std::vector<float> va, vb;
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < a.cols; ++c)
      if (mask.empty() || mask.at<uint8_t>(r, c)) {
        va.push_back(a.at<float>(r, c));
        vb.push_back(b.at<float>(r, c));
      }
  if (static_cast<int>(va.size()) < o.min_pixels)
    return Status::Error("photometric registration: " + std::to_string(va.size()) +
                         " overlapping pixels, need " + std::to_string(o.min_pixels));
  std::vector<bool> keep(va.size(), true);
  auto first = fitLine(va, vb, keep);
  if (!first.ok()) return first;
  // Orthogonal residuals of the first fit; drop those beyond outlier_sigma·σ and refit.
  const double norm = std::sqrt(1.0 + first->gain * first->gain);
  std::vector<double> res(va.size());
  double s2 = 0.0;
  for (std::size_t i = 0; i < va.size(); ++i) {
    res[i] = (vb[i] - first->gain * va[i] - first->bias) / norm;
    s2 += res[i] * res[i];
  }
  const double sigma = std::sqrt(s2 / static_cast<double>(va.size()));
  for (std::size_t i = 0; i < va.size(); ++i)
    keep[i] = std::abs(res[i]) <= o.outlier_sigma * sigma + 1e-9;
  auto g = fitLine(va, vb, keep);
  if (!g.ok()) return g;
  if (g->pixels < o.min_pixels) return Status::Error("photometric registration: too few inliers");
  if (std::abs(g->gain - 1.0) > o.max_gain_change)
    return Status::Error("photometric registration: implausible gain " + std::to_string(g->gain));
  return g;
}

}  // namespace cvslam::mosaic
