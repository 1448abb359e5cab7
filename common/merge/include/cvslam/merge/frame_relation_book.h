#pragma once
// Which frame relations an agent believes in, per peer: "not yet found", or one adopted
// relation that later verifications refine. Built so that a wrong merge is rarer than a missed
// one (users lose whole maps to the former):
//  - A verified hypothesis (four_dof_aligner.h) is only a candidate. A relation is adopted when
//    `adopt_after` candidates agree pairwise — the largest such group, as in pairwise
//    consistency maximisation (PCM, Mangelson et al. 2018) — and each pair was verified at
//    least `min_separation_s` apart (other keyframes, other landmarks: independent evidence).
//  - Two candidates agree when their difference passes a χ²₄ gate on the covariance
//    intersection bound (covariance_intersection.h, ciBoundedNis): the candidates of one
//    agent's map are correlated in unknown ways (one filter made all their landmarks), and the
//    bound holds for any correlation.
//  - The adopted relation is the group's covariance-intersection fusion (consistent whatever
//    their correlation); every later candidate is a gated measurement of it: fused when it
//    passes, refused with the reason when it does not.
//  - forget(peer) drops everything about a peer (a restarted peer: new boot id).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/merge/frame_relation.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::merge {

struct FrameRelationBookOptions {
  int adopt_after = 3;                    ///< agreeing candidates needed to adopt a relation
  double consistency_probability = 0.99;  ///< χ²₄ gate of agreement and of later refinements
  double min_separation_s = 2.0;          ///< candidates closer in time are not independent [s]
  int max_candidates = 32;                ///< per peer, before adoption; the oldest are dropped

  Status load(const ConfigNode& node);
};

/// One verified hypothesis of a peer's frame in ours.
struct RelationCandidate {
  FrameRelation relation;  ///< peer's frame → ours
  double t_s = 0.0;        ///< when it was verified (our clock) [s]
  int inliers = 0;         ///< correspondences that supported it
};

enum class RelationVerdict {
  kPending,   ///< kept as a candidate; not enough agreement yet
  kAdopted,   ///< this candidate completed a group: the relation is now adopted
  kRefined,   ///< passed the gate of the adopted relation and was fused into it
  kRejected,  ///< refused (the reason says why)
};

struct RelationDecision {
  RelationVerdict verdict = RelationVerdict::kPending;
  std::string reason;  ///< one line for the log
  double nis = 0.0;    ///< against the adopted relation (kRefined, kRejected), else 0
  int agreeing = 0;    ///< kPending / kAdopted: size of the largest agreeing group with it
};

/// "pending" | "adopted" | "refined" | "rejected".
const char* relationVerdictName(RelationVerdict verdict);

class FrameRelationBook {
 public:
  explicit FrameRelationBook(const FrameRelationBookOptions& options = {});

  /// A new verified candidate for `peer`'s frame.
  RelationDecision offer(int peer, const RelationCandidate& candidate);

  /// The adopted relation of `peer` (its frame → ours), or nullopt ("not yet found").
  std::optional<FrameRelation> relation(int peer) const;
  /// The peers whose relation is adopted, ascending.
  std::vector<int> adoptedPeers() const;
  /// When the relation of `peer` was adopted [s], or nullopt.
  std::optional<double> adoptedAt(int peer) const;
  /// Candidates waiting for agreement (before adoption).
  std::size_t pendingCount(int peer) const;
  /// Drops every candidate and the relation of `peer`.
  void forget(int peer);

 private:
  struct Peer {
    std::vector<RelationCandidate> candidates;
    std::optional<FrameRelation> adopted;
    double adopted_at_s = 0.0;
  };
  bool agree(const RelationCandidate& a, const RelationCandidate& b) const;
  std::vector<std::size_t> largestAgreeingGroup(const std::vector<RelationCandidate>& c,
                                                std::size_t with) const;
  static Expected<FrameRelation> fuse(const FrameRelation& a, const FrameRelation& b);

  FrameRelationBookOptions o_;
  double gate_ = 0.0;
  std::map<int, Peer> peers_;
};

}  // namespace cvslam::merge
