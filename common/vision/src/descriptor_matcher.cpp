#include "cvslam/vision/descriptor_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

Status MatchOptions::load(const ConfigNode& node) {
  node.getEnum("norm", norm,
               {{"linf", MatchNorm::kLinf},
                {"l2", MatchNorm::kL2},
                {"angle", MatchNorm::kAngle},
                {"hamming", MatchNorm::kHamming}});
  node.get("dist_ratio", dist_ratio);
  node.get("max_distance", max_distance);
  node.get("mutual", mutual);
  node.get("accept_single_candidate", accept_single_candidate);
  node.check(dist_ratio > 0 && dist_ratio <= 1, "dist_ratio", "must be in (0, 1]");
  node.check(max_distance >= 0, "max_distance", "must be >= 0");
  return node.status();
}

MatchNorm effectiveNorm(MatchNorm requested, DescriptorType type) {
  if (type == DescriptorType::kOrb) return MatchNorm::kHamming;
  return requested == MatchNorm::kHamming ? MatchNorm::kL2 : requested;
}

namespace {

// Distances are compared in an integer surrogate where possible (L∞, squared L2, Hamming)
// or −cos for the angle, and converted once for the ratio test. The criterion is a template
// parameter so that each inner loop inlines its distance.
template <MatchNorm kNorm>
struct Scorer {
  int n;
  const std::vector<double>* query_norms;
  const std::vector<double>* train_norms;

  double operator()(const uint8_t* a, int i, const uint8_t* b, int j) const {
    if constexpr (kNorm == MatchNorm::kLinf) return distanceLinf(a, b, n);
    if constexpr (kNorm == MatchNorm::kL2) return distanceL2Squared(a, b, n);
    if constexpr (kNorm == MatchNorm::kHamming) return distanceHamming(a, b, n);
    if constexpr (kNorm == MatchNorm::kAngle) {
      const double nn =
          (*query_norms)[static_cast<std::size_t>(i)] * (*train_norms)[static_cast<std::size_t>(j)];
      return nn > 0 ? -dotProduct(a, b, n) / nn : 0.0;  // −cos: smaller is better
    }
    return 0.0;
  }
  static double distance(double score) {
    if constexpr (kNorm == MatchNorm::kL2) return std::sqrt(score);
    if constexpr (kNorm == MatchNorm::kAngle) return std::acos(std::clamp(-score, -1.0, 1.0));
    return score;
  }
};

std::vector<double> norms(const Features& f, int n) {
  std::vector<double> out(f.size());
  for (std::size_t i = 0; i < f.size(); ++i)
    out[i] = std::sqrt(static_cast<double>(dotProduct(f.descriptor(i), f.descriptor(i), n)));
  return out;
}

template <MatchNorm kNorm>
std::vector<Match> matchImpl(const Features& query, const Features& train, const MatchOptions& o,
                             const std::vector<std::vector<int>>* candidates) {
  std::vector<Match> out;
  const int bytes = descriptorBytes(query.type);
  std::vector<double> qn, tn;
  if constexpr (kNorm == MatchNorm::kAngle) {
    qn = norms(query, bytes);
    tn = norms(train, bytes);
  }
  const Scorer<kNorm> scorer{bytes, &qn, &tn};
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Reverse bests for the mutual check: best score of each train feature over all queries
  // that considered it.
  std::vector<double> train_best(train.size(), kInf);
  std::vector<int> train_best_query(train.size(), -1);
  const int nq = static_cast<int>(query.size());
  const int nt = static_cast<int>(train.size());
  const uint8_t* tdata = train.descriptors.ptr<uint8_t>(0);
  const std::size_t tstep = train.descriptors.step[0];
  for (int i = 0; i < nq; ++i) {
    const uint8_t* qd = query.descriptor(static_cast<std::size_t>(i));
    double s1 = kInf;
    double s2 = kInf;
    int j1 = -1;
    auto consider = [&](int j) {
      const double s = scorer(qd, i, tdata + static_cast<std::size_t>(j) * tstep, j);
      if (s < s1) {
        s2 = s1;
        s1 = s;
        j1 = j;
      } else if (s < s2) {
        s2 = s;
      }
      if (s < train_best[static_cast<std::size_t>(j)]) {
        train_best[static_cast<std::size_t>(j)] = s;
        train_best_query[static_cast<std::size_t>(j)] = i;
      }
    };
    if (candidates) {
      for (int j : (*candidates)[static_cast<std::size_t>(i)]) consider(j);
    } else {
      for (int j = 0; j < nt; ++j) consider(j);
    }
    if (j1 < 0) continue;
    const double d1 = scorer.distance(s1);
    if (o.max_distance > 0 && d1 > o.max_distance) continue;
    if (s2 == kInf) {
      if (!(o.accept_single_candidate && o.max_distance > 0)) continue;
    } else if (!(d1 < o.dist_ratio * scorer.distance(s2))) {
      continue;
    }
    out.push_back({i, j1, d1});
  }
  if (o.mutual) {
    out.erase(std::remove_if(out.begin(), out.end(),
                             [&](const Match& m) {
                               return train_best_query[static_cast<std::size_t>(m.train)] !=
                                      m.query;
                             }),
              out.end());
  }
  return out;
}

}  // namespace

std::vector<Match> matchDescriptors(const Features& query, const Features& train,
                                    const MatchOptions& o,
                                    const std::vector<std::vector<int>>* candidates) {
  if (query.size() == 0 || train.size() == 0 || query.type != train.type) return {};
  switch (effectiveNorm(o.norm, query.type)) {
    case MatchNorm::kLinf:
      return matchImpl<MatchNorm::kLinf>(query, train, o, candidates);
    case MatchNorm::kL2:
      return matchImpl<MatchNorm::kL2>(query, train, o, candidates);
    case MatchNorm::kAngle:
      return matchImpl<MatchNorm::kAngle>(query, train, o, candidates);
    case MatchNorm::kHamming:
      return matchImpl<MatchNorm::kHamming>(query, train, o, candidates);
  }
  return {};
}

std::vector<std::vector<int>> candidatesNear(const std::vector<cv::Point2f>& predicted,
                                             const Features& train, double radius_px) {
  std::vector<int> by_row(train.size());
  for (std::size_t j = 0; j < train.size(); ++j) by_row[j] = static_cast<int>(j);
  auto row = [&](int j) { return train.keypoints[static_cast<std::size_t>(j)].pt.y; };
  std::sort(by_row.begin(), by_row.end(), [&](int a, int b) { return row(a) < row(b); });
  std::vector<float> rows(by_row.size());
  for (std::size_t k = 0; k < by_row.size(); ++k) rows[k] = row(by_row[k]);
  const double r2 = radius_px * radius_px;
  std::vector<std::vector<int>> out(predicted.size());
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    const cv::Point2f p = predicted[i];
    auto lo = std::lower_bound(rows.begin(), rows.end(), static_cast<float>(p.y - radius_px));
    auto hi = std::upper_bound(rows.begin(), rows.end(), static_cast<float>(p.y + radius_px));
    for (auto it = lo; it != hi; ++it) {
      const int j = by_row[static_cast<std::size_t>(it - rows.begin())];
      const cv::Point2f q = train.keypoints[static_cast<std::size_t>(j)].pt;
      const double dx = q.x - p.x;
      const double dy = q.y - p.y;
      if (dx * dx + dy * dy <= r2) out[i].push_back(j);
    }
  }
  return out;
}

std::vector<Match> filterByScaleRate(const std::vector<Match>& matches, const Features& query,
                                     const Features& train, double expected,
                                     double tolerance_log2) {
  if (matches.empty() || tolerance_log2 <= 0) return matches;
  std::vector<double> log_rates;
  log_rates.reserve(matches.size());
  for (const Match& m : matches) {
    const double sq = query.keypoints[static_cast<std::size_t>(m.query)].size;
    const double st = train.keypoints[static_cast<std::size_t>(m.train)].size;
    log_rates.push_back(sq > 0 && st > 0 ? std::log2(st / sq) : 0.0);
  }
  double centre = 0.0;
  if (expected > 0) {
    centre = std::log2(expected);
  } else {
    std::vector<double> sorted = log_rates;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                     sorted.end());
    centre = sorted[sorted.size() / 2];
  }
  std::vector<Match> out;
  for (std::size_t k = 0; k < matches.size(); ++k)
    if (std::abs(log_rates[k] - centre) <= tolerance_log2) out.push_back(matches[k]);
  return out;
}

}  // namespace cvslam::vision
