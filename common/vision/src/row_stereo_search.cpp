#include "cvslam/vision/row_stereo_search.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

namespace {

// ZNCC of a patch against a flat one is undefined (0/0); such candidates score 0.
float znccOf(float num, float sum, float sq, float n, float left_norm, float min_var) {
  const float var = sq - sum * sum / n;
  return var > min_var ? num / (left_norm * std::sqrt(var)) : 0.0f;
}
constexpr int kSecondPeakGap = 2;  // the second best lies this far from the best [px]

// Vertex of the parabola through (−1, a), (0, b), (1, c), clamped to ±limit.
float parabolaPeak(float a, float b, float c, float limit) {
  const float denom = a - 2.0f * b + c;
  if (!(denom < 0.0f)) return 0.0f;
  return std::clamp(0.5f * (a - c) / denom, -limit, limit);
}

}  // namespace

Status RowSearchOptions::load(const ConfigNode& node) {
  node.get("patch_radius", patch_radius);
  node.get("min_zncc", min_zncc);
  node.get("uniqueness", uniqueness);
  node.get("min_patch_std", min_patch_std);
  node.check(patch_radius >= 1 && patch_radius <= 15, "patch_radius", "must be in [1, 15]");
  node.check(min_zncc > -1.0 && min_zncc < 1.0, "min_zncc", "must be in (−1, 1)");
  node.check(uniqueness > 0.0 && uniqueness <= 1.0, "uniqueness", "must be in (0, 1]");
  node.check(min_patch_std >= 0.0, "min_patch_std", "must be >= 0");
  return node.status();
}

double RowStereoSearch::zncc(int x, int y) const {
  const int r = radius_;
  float num = 0, sum = 0, sq = 0;
  for (int i = -r; i <= r; ++i) {
    const float* R = right_f_.ptr<float>(y + i) + x - r;
    const float* P = patch_.data() + (i + r) * (2 * r + 1);
    for (int j = 0; j <= 2 * r; ++j) {
      const float q = R[j] - patch_mean_;
      num += q * P[j];
      sum += q;
      sq += q * q;
    }
  }
  const float n = static_cast<float>((2 * r + 1) * (2 * r + 1));
  return znccOf(num, sum, sq, n, patch_norm_, min_var_);
}

bool RowStereoSearch::searchOne(const cv::KeyPoint& kp, int dlo, int dhi, double vd_max,
                                const RowSearchOptions& o, RowStereoMatch* match) {
  const int r = radius_;
  const int side = 2 * r + 1;
  const float n = static_cast<float>(side * side);
  const int u = static_cast<int>(std::lround(kp.pt.x));
  const int v = static_cast<int>(std::lround(kp.pt.y));
  const cv::Mat& L = left_f_;
  if (v - r - 1 < 0 || v + r + 1 >= L.rows || u - r < 0 || u + r >= L.cols) return false;
  // The zero-mean left patch and its norm.
  float mean = 0;
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j) mean += L.at<float>(v + i, u + j);
  mean /= n;
  float norm2 = 0;
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j) {
      const float z = L.at<float>(v + i, u + j) - mean;
      patch_[static_cast<std::size_t>((i + r) * side + j + r)] = z;
      norm2 += z * z;
    }
  min_var_ = static_cast<float>(o.min_patch_std * o.min_patch_std) * n;  // both patches
  if (norm2 < min_var_) return false;
  patch_norm_ = std::sqrt(norm2);
  patch_mean_ = mean;
  // Candidate centres x = u − d for d in [dlo − 1, dhi + 1] (±1 for the parabola).
  const int xmin = std::max(u - (dhi + 1), r);
  const int xmax = std::min(u - (dlo - 1), L.cols - 1 - r);
  const int m = xmax - xmin + 1;
  if (m < 3) return false;
  num_.assign(static_cast<std::size_t>(m), 0.0f);
  sum_.assign(static_cast<std::size_t>(m), 0.0f);
  sq_.assign(static_cast<std::size_t>(m), 0.0f);
  float* num = num_.data();
  float* sum = sum_.data();
  float* sq = sq_.data();
  for (int i = -r; i <= r; ++i) {
    const float* row = right_f_.ptr<float>(v + i) + xmin - r;
    const float* P = patch_.data() + (i + r) * side;
    for (int j = 0; j < side; ++j) {
      const float p = P[j];
      const float* R = row + j;
      // Grey levels relative to the left patch's mean: the variance Σq² − (Σq)²/n is then a
      // difference of small sums (in absolute grey levels float cancellation ruins it).
      for (int x = 0; x < m; ++x) {  // contiguous over candidates: vectorises
        const float q = R[x] - mean;
        num[x] += q * p;
        sum[x] += q;
        sq[x] += q * q;
      }
    }
  }
  score_.resize(static_cast<std::size_t>(m));
  for (int x = 0; x < m; ++x)
    score_[static_cast<std::size_t>(x)] = znccOf(num[x], sum[x], sq[x], n, patch_norm_, min_var_);
  // Best inside the disparity window proper (not the ±1 padding), then the second best.
  const int lo = std::max(0, u - dhi - xmin);
  const int hi = std::min(m - 1, u - dlo - xmin);
  if (hi < lo) return false;
  int best = lo;
  for (int x = lo; x <= hi; ++x)
    if (score_[static_cast<std::size_t>(x)] > score_[static_cast<std::size_t>(best)]) best = x;
  float second = -1.0f;
  for (int x = lo; x <= hi; ++x)
    if (std::abs(x - best) >= kSecondPeakGap)
      second = std::max(second, score_[static_cast<std::size_t>(x)]);
  const float s0 = score_[static_cast<std::size_t>(best)];
  if (s0 < o.min_zncc || 1.0f - s0 >= static_cast<float>(o.uniqueness) * (1.0f - second))
    return false;
  if (best == 0 || best == m - 1) return false;  // no neighbour for the parabola: image border
  const float dx = parabolaPeak(score_[static_cast<std::size_t>(best - 1)], s0,
                                score_[static_cast<std::size_t>(best + 1)], 0.5f);
  const int xr = xmin + best;
  float dy = 0.0f;
  if (vd_max > 0.0) {
    const float limit = static_cast<float>(std::min(vd_max, 0.5));  // half a row at most
    dy = parabolaPeak(static_cast<float>(zncc(xr, v - 1)), s0, static_cast<float>(zncc(xr, v + 1)),
                      limit);
  }
  match->right = cv::Point2f(kp.pt.x - static_cast<float>(u - xr) + dx, kp.pt.y + dy);
  match->score = s0;
  return true;
}

void RowStereoSearch::search(const cv::Mat& left, const cv::Mat& right,
                             const std::vector<cv::KeyPoint>& keypoints,
                             const StereoMatchOptions& stereo, const RowSearchOptions& o,
                             std::vector<RowStereoMatch>* matches) {
  matches->clear();
  left.convertTo(left_f_, CV_32F);
  right.convertTo(right_f_, CV_32F);
  radius_ = o.patch_radius;
  patch_.resize(static_cast<std::size_t>((2 * radius_ + 1) * (2 * radius_ + 1)));
  // Integer disparities searched: d > min_disparity (strict, eq. 4.9) up to HD_max.
  const int dlo = std::max(1, static_cast<int>(std::floor(stereo.min_disparity_px)) + 1);
  const int dhi = static_cast<int>(std::floor(stereo.maxHorizontalDisparity()));
  if (dhi < dlo) return;
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    RowStereoMatch m;
    m.left = static_cast<int>(i);
    if (searchOne(keypoints[i], dlo, dhi, stereo.max_vertical_disparity_px, o, &m)) {
      const double d = keypoints[i].pt.x - m.right.x;
      if (d > stereo.min_disparity_px && d <= stereo.maxHorizontalDisparity())
        matches->push_back(m);
    }
  }
}

}  // namespace cvslam::vision
