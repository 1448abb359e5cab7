#include "cvslam/merge/frame_relation_book.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cvslam/filter/chi_square.h"
#include "cvslam/filter/covariance_intersection.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/io/config_node.h"

namespace cvslam::merge {

namespace {

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

}  // namespace

const char* relationVerdictName(RelationVerdict verdict) {
  switch (verdict) {
    case RelationVerdict::kPending:
      return "pending";
    case RelationVerdict::kAdopted:
      return "adopted";
    case RelationVerdict::kRefined:
      return "refined";
    case RelationVerdict::kRejected:
      return "rejected";
  }
  return "?";
}

Status FrameRelationBookOptions::load(const ConfigNode& node) {
  node.get("adopt_after", adopt_after);
  node.get("consistency_probability", consistency_probability);
  node.get("min_separation_s", min_separation_s);
  node.get("max_candidates", max_candidates);
  node.check(adopt_after >= 1, "adopt_after", "must be >= 1");
  node.check(consistency_probability > 0.0 && consistency_probability < 1.0,
             "consistency_probability", "must be in (0, 1)");
  node.check(min_separation_s >= 0.0, "min_separation_s", "must be >= 0 s");
  node.check(max_candidates >= adopt_after, "max_candidates", "must be >= adopt_after");
  return node.status();
}

FrameRelationBook::FrameRelationBook(const FrameRelationBookOptions& options)
    : o_(options), gate_(chiSquareQuantile(options.consistency_probability, 4)) {}

bool FrameRelationBook::agree(const RelationCandidate& a, const RelationCandidate& b) const {
  if (std::abs(a.t_s - b.t_s) < o_.min_separation_s) return false;
  const Eigen::VectorXd d = relationDifference(a.relation.x, b.relation.x);
  return ciBoundedNis(d, a.relation.P, b.relation.P) <= gate_;
}

std::vector<std::size_t> FrameRelationBook::largestAgreeingGroup(
    const std::vector<RelationCandidate>& c, std::size_t with) const {
  // A maximum clique containing `with` in the agreement graph. The book holds at most
  // max_candidates (32) candidates, so an exhaustive search over `with`'s neighbours, pruned by
  // size, is cheap; greedy orders would miss the group that a wrong early candidate hides.
  std::vector<std::size_t> neighbours;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (i != with && agree(c[i], c[with])) neighbours.push_back(i);
  std::vector<std::size_t> best{with};
  std::vector<std::size_t> current{with};
  // Depth-first over subsets of `neighbours` in index order.
  auto search = [&](auto&& self, std::size_t from) -> void {
    if (current.size() > best.size()) best = current;
    if (current.size() + (neighbours.size() - from) <= best.size()) return;
    for (std::size_t k = from; k < neighbours.size(); ++k) {
      const std::size_t v = neighbours[k];
      bool ok = true;
      for (std::size_t u : current)
        if (u != with && !agree(c[u], c[v])) {
          ok = false;
          break;
        }
      if (!ok) continue;
      current.push_back(v);
      self(self, k + 1);
      current.pop_back();
    }
  };
  search(search, 0);
  return best;
}

Expected<FrameRelation> FrameRelationBook::fuse(const FrameRelation& a, const FrameRelation& b) {
  // Yaw of b taken to within π of a's before the weighted mean.
  Eigen::VectorXd xb = b.x;
  xb(3) = a.x(3) + wrapAngle(b.x(3) - a.x(3));
  const double omega = optimalCiOmega(a.P, b.P, false);
  auto fused = fuseCovarianceIntersection(a.x, a.P, xb, b.P, omega);
  if (!fused.ok()) return fused.status();
  FrameRelation out;
  out.x = fused->x;
  out.x(3) = wrapAngle(out.x(3));
  out.P = fused->P;
  return out;
}

RelationDecision FrameRelationBook::offer(int peer, const RelationCandidate& candidate) {
  RelationDecision d;
  Peer& p = peers_[peer];
  if (!candidate.relation.x.allFinite() || !candidate.relation.P.allFinite()) {
    d.verdict = RelationVerdict::kRejected;
    d.reason = "non-finite candidate";
    return d;
  }
  if (p.adopted) {
    const Eigen::VectorXd diff = relationDifference(candidate.relation.x, p.adopted->x);
    d.nis = ciBoundedNis(diff, candidate.relation.P, p.adopted->P);
    const double dt = diff.head<3>().norm();
    const double dyaw = std::abs(diff(3)) * 180.0 / M_PI;
    if (d.nis > gate_) {
      d.verdict = RelationVerdict::kRejected;
      d.reason = format("disagrees with the adopted relation: NIS %.1f > gate %.1f (%.2f m", d.nis,
                        gate_, dt) +
                 format(", %.1f deg off)", dyaw);
      return d;
    }
    auto fused = fuse(*p.adopted, candidate.relation);
    if (!fused.ok()) {
      d.verdict = RelationVerdict::kRejected;
      d.reason = "cannot fuse: " + fused.status().message();
      return d;
    }
    p.adopted = *fused;
    d.verdict = RelationVerdict::kRefined;
    d.reason = format("within the gate: NIS %.1f (%.2f m, %.1f deg off)", d.nis, dt, dyaw);
    return d;
  }
  p.candidates.push_back(candidate);
  if (p.candidates.size() > static_cast<std::size_t>(o_.max_candidates))
    p.candidates.erase(p.candidates.begin());
  const std::vector<std::size_t> group =
      largestAgreeingGroup(p.candidates, p.candidates.size() - 1);
  d.agreeing = static_cast<int>(group.size());
  if (group.size() < static_cast<std::size_t>(o_.adopt_after)) {
    d.verdict = RelationVerdict::kPending;
    d.reason = std::to_string(group.size()) + " agreeing of " + std::to_string(o_.adopt_after) +
               " needed (" + std::to_string(p.candidates.size()) + " candidates)";
    return d;
  }
  FrameRelation fused = p.candidates[group.front()].relation;
  for (std::size_t k = 1; k < group.size(); ++k) {
    auto f = fuse(fused, p.candidates[group[k]].relation);
    if (!f.ok()) {
      d.verdict = RelationVerdict::kRejected;
      d.reason = "cannot fuse the agreeing group: " + f.status().message();
      return d;
    }
    fused = *f;
  }
  p.adopted = fused;
  p.adopted_at_s = candidate.t_s;
  p.candidates.clear();
  d.verdict = RelationVerdict::kAdopted;
  d.reason = std::to_string(group.size()) + " candidates agree";
  return d;
}

std::vector<int> FrameRelationBook::adoptedPeers() const {
  std::vector<int> out;
  for (const auto& [peer, p] : peers_)
    if (p.adopted) out.push_back(peer);
  return out;
}

std::optional<FrameRelation> FrameRelationBook::relation(int peer) const {
  const auto it = peers_.find(peer);
  if (it == peers_.end()) return std::nullopt;
  return it->second.adopted;
}

std::optional<double> FrameRelationBook::adoptedAt(int peer) const {
  const auto it = peers_.find(peer);
  if (it == peers_.end() || !it->second.adopted) return std::nullopt;
  return it->second.adopted_at_s;
}

std::size_t FrameRelationBook::pendingCount(int peer) const {
  const auto it = peers_.find(peer);
  return it == peers_.end() ? 0 : it->second.candidates.size();
}

void FrameRelationBook::forget(int peer) {
  peers_.erase(peer);
}

}  // namespace cvslam::merge
