#include "cvslam/vision/detector_eval.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

namespace cvslam::vision {

namespace {

constexpr double kRansacConfidence = 0.999;
constexpr int kMinFundamentalMatches = 8;  // the 8-point algorithm

cv::Point2d apply(const cv::Matx33d& H, const cv::Point2f& p) {
  const cv::Vec3d q = H * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

bool inside(const cv::Point2d& p, cv::Size s) {
  return p.x >= 0 && p.y >= 0 && p.x <= s.width - 1 && p.y <= s.height - 1;
}

MatchQuality finish(const Features& a, const Features& b, const std::vector<Match>& m,
                    int correct) {
  MatchQuality q;
  q.features = static_cast<int>(std::min(a.size(), b.size()));
  q.matches = static_cast<int>(m.size());
  q.correct = correct;
  q.precision = m.empty() ? 0.0 : static_cast<double>(correct) / static_cast<double>(m.size());
  q.matching_score = q.features == 0 ? 0.0 : static_cast<double>(correct) / q.features;
  return q;
}

}  // namespace

RepeatabilityResult repeatability(const std::vector<cv::KeyPoint>& a, cv::Size size_a,
                                  const std::vector<cv::KeyPoint>& b, cv::Size size_b,
                                  const cv::Matx33d& H_ab, double eps_px) {
  RepeatabilityResult r;
  const cv::Matx33d H_ba = H_ab.inv();
  std::vector<cv::Point2d> mapped;  // visible features of a, in b
  for (const cv::KeyPoint& k : a) {
    const cv::Point2d p = apply(H_ab, k.pt);
    if (inside(p, size_b)) mapped.push_back(p);
  }
  std::vector<cv::Point2f> visible_b;
  for (const cv::KeyPoint& k : b)
    if (inside(apply(H_ba, k.pt), size_a)) visible_b.push_back(k.pt);
  r.visible_a = static_cast<int>(mapped.size());
  r.visible_b = static_cast<int>(visible_b.size());
  // One-to-one: all pairs within eps, closest first, each feature used once.
  struct Pair {
    double d2;
    int i, j;
  };
  std::vector<Pair> pairs;
  const double eps2 = eps_px * eps_px;
  for (std::size_t i = 0; i < mapped.size(); ++i)
    for (std::size_t j = 0; j < visible_b.size(); ++j) {
      const double dx = mapped[i].x - visible_b[j].x, dy = mapped[i].y - visible_b[j].y;
      const double d2 = dx * dx + dy * dy;
      if (d2 <= eps2) pairs.push_back({d2, static_cast<int>(i), static_cast<int>(j)});
    }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) {
    return x.d2 < y.d2 || (x.d2 == y.d2 && (x.i < y.i || (x.i == y.i && x.j < y.j)));
  });
  std::vector<char> used_a(mapped.size(), 0), used_b(visible_b.size(), 0);
  for (const Pair& p : pairs) {
    if (used_a[static_cast<std::size_t>(p.i)] || used_b[static_cast<std::size_t>(p.j)]) continue;
    used_a[static_cast<std::size_t>(p.i)] = used_b[static_cast<std::size_t>(p.j)] = 1;
    ++r.correspondences;
  }
  const int denom = std::min(r.visible_a, r.visible_b);
  r.repeatability = denom > 0 ? static_cast<double>(r.correspondences) / denom : 0.0;
  return r;
}

MatchQuality matchQualityHomography(const Features& a, const Features& b,
                                    const std::vector<Match>& matches, const cv::Matx33d& H_ab,
                                    double eps_px) {
  int correct = 0;
  for (const Match& m : matches) {
    const cv::Point2d p = apply(H_ab, a.keypoints[static_cast<std::size_t>(m.query)].pt);
    const cv::Point2f& q = b.keypoints[static_cast<std::size_t>(m.train)].pt;
    if (std::hypot(p.x - q.x, p.y - q.y) <= eps_px) ++correct;
  }
  return finish(a, b, matches, correct);
}

MatchQuality matchQualityFundamental(const Features& a, const Features& b,
                                     const std::vector<Match>& matches, double eps_px) {
  if (static_cast<int>(matches.size()) < kMinFundamentalMatches) return finish(a, b, matches, 0);
  std::vector<cv::Point2f> pa, pb;
  for (const Match& m : matches) {
    pa.push_back(a.keypoints[static_cast<std::size_t>(m.query)].pt);
    pb.push_back(b.keypoints[static_cast<std::size_t>(m.train)].pt);
  }
  std::vector<uchar> inliers;
  const cv::Mat F =
      cv::findFundamentalMat(pa, pb, cv::FM_RANSAC, eps_px, kRansacConfidence, inliers);
  const int correct = F.empty() ? 0 : cv::countNonZero(inliers);
  return finish(a, b, matches, correct);
}

MatchQuality matchQualityStereo(const Features& a, const Features& b,
                                const std::vector<Match>& matches, double eps_px,
                                double min_disparity, double max_disparity) {
  int correct = 0;
  for (const Match& m : matches) {
    const cv::Point2f& p = a.keypoints[static_cast<std::size_t>(m.query)].pt;
    const cv::Point2f& q = b.keypoints[static_cast<std::size_t>(m.train)].pt;
    const double disparity = p.x - q.x;
    if (std::fabs(p.y - q.y) <= eps_px && disparity >= min_disparity && disparity <= max_disparity)
      ++correct;
  }
  return finish(a, b, matches, correct);
}

}  // namespace cvslam::vision
