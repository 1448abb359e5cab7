#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cvslam/merge/frame_relation_book.h"
#include "merge/merge_test_scenes.h"

namespace cvslam::merge {
namespace {

// A verified candidate: the truth plus an error drawn from its own covariance.
RelationCandidate candidate(Rng& rng, const FrameRelation& truth, double t_s, double scale = 1.0) {
  RelationCandidate c;
  c.t_s = t_s;
  c.inliers = 30;
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  A.diagonal() << 0.05, 0.05, 0.03, 0.004;
  A *= scale;
  c.relation.P = A * A.transpose();
  Eigen::Vector4d e(rng.gaussian(), rng.gaussian(), rng.gaussian(), rng.gaussian());
  c.relation.x = truth.x + A * e;
  return c;
}

FrameRelation truthRelation() {
  FrameRelation t;
  t.x << 10.0, -3.0, 0.5, 1.2;
  return t;
}

TEST(FrameRelationBook, AdoptsWhenEnoughIndependentCandidatesAgree) {
  Rng rng(1);
  FrameRelationBook book;
  const FrameRelation truth = truthRelation();
  EXPECT_EQ(book.offer(2, candidate(rng, truth, 0.0)).verdict, RelationVerdict::kPending);
  // Verified again half a second later: the same keyframes' evidence, not counted.
  const RelationDecision close = book.offer(2, candidate(rng, truth, 0.5));
  EXPECT_EQ(close.verdict, RelationVerdict::kPending);
  EXPECT_EQ(close.agreeing, 1);
  EXPECT_EQ(book.offer(2, candidate(rng, truth, 3.0)).verdict, RelationVerdict::kPending);
  EXPECT_FALSE(book.relation(2).has_value());
  const RelationDecision adopted = book.offer(2, candidate(rng, truth, 6.0));
  EXPECT_EQ(adopted.verdict, RelationVerdict::kAdopted) << adopted.reason;
  ASSERT_TRUE(book.relation(2).has_value());
  EXPECT_EQ(*book.adoptedAt(2), 6.0);
  EXPECT_FALSE(book.relation(3).has_value());  // per peer
  EXPECT_EQ(book.pendingCount(2), 0u);
}

TEST(FrameRelationBook, AWrongCandidateNeverJoinsTheGroup) {
  Rng rng(2);
  FrameRelationBook book;
  const FrameRelation truth = truthRelation();
  FrameRelation wrong = truth;
  wrong.x(0) += 4.0;  // a repeated structure four metres over
  EXPECT_EQ(book.offer(5, candidate(rng, wrong, 0.0)).verdict, RelationVerdict::kPending);
  EXPECT_EQ(book.offer(5, candidate(rng, truth, 3.0)).verdict, RelationVerdict::kPending);
  EXPECT_EQ(book.offer(5, candidate(rng, wrong, 6.0)).verdict, RelationVerdict::kPending);
  EXPECT_EQ(book.offer(5, candidate(rng, truth, 9.0)).verdict, RelationVerdict::kPending);
  const RelationDecision d = book.offer(5, candidate(rng, truth, 12.0));
  ASSERT_EQ(d.verdict, RelationVerdict::kAdopted) << d.reason;
  EXPECT_LT(std::abs(book.relation(5)->x(0) - truth.x(0)), 0.3);
  // Adopted: a later wrong candidate is refused with why, a right one refines.
  const RelationDecision refused = book.offer(5, candidate(rng, wrong, 15.0));
  EXPECT_EQ(refused.verdict, RelationVerdict::kRejected);
  EXPECT_NE(refused.reason.find("NIS"), std::string::npos) << refused.reason;
  const double before = book.relation(5)->P.trace();
  const RelationDecision refined = book.offer(5, candidate(rng, truth, 18.0));
  EXPECT_EQ(refined.verdict, RelationVerdict::kRefined) << refined.reason;
  EXPECT_LE(book.relation(5)->P.trace(), before);
  book.forget(5);
  EXPECT_FALSE(book.relation(5).has_value());
}

TEST(FrameRelationBook, MutuallyInconsistentCandidatesAreNeverAdopted) {
  // A place recogniser fooled everywhere: every candidate somewhere else.
  Rng rng(3);
  FrameRelationBook book;
  for (int k = 0; k < 100; ++k) {
    FrameRelation random;
    random.x << rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-2, 2),
        rng.uniform(-M_PI, M_PI);
    EXPECT_NE(book.offer(1, candidate(rng, random, 3.0 * k)).verdict, RelationVerdict::kAdopted);
  }
  EXPECT_FALSE(book.relation(1).has_value());
  EXPECT_LE(book.pendingCount(1), 32u);
}

TEST(FrameRelationBook, AdoptedRelationsAreConsistentOverAMonteCarlo) {
  // Candidates of one map share errors; with a common error and covariance-intersection fusion
  // the adopted relation must not claim more than it knows.
  Rng rng(4);
  double nees = 0.0;
  const int trials = 200;
  for (int t = 0; t < trials; ++t) {
    FrameRelationBook book;
    const FrameRelation truth = truthRelation();
    const RelationCandidate shared = candidate(rng, truth, 0.0, 0.7);
    const FrameRelation::Vector4d common = shared.relation.x - truth.x;
    std::optional<FrameRelation> adopted;
    for (int k = 0; k < 3; ++k) {
      RelationCandidate c = candidate(rng, truth, 3.0 * k, 0.7);
      c.relation.x += common;  // correlated errors
      c.relation.P *= 2.0;     // each stated with its whole error (0.7² · 2 ≈ 1)
      book.offer(1, c);
    }
    adopted = book.relation(1);
    ASSERT_TRUE(adopted.has_value());
    nees += scenes::relationNees(*adopted, truth);
  }
  nees /= trials;
  std::printf("adopted relation NEES over %d trials: %.2f\n", trials, nees);
  EXPECT_LT(nees, 4.0 + 2.58 * std::sqrt(8.0 / trials));
}

TEST(FrameRelationBook, NonFiniteCandidatesAreRefused) {
  FrameRelationBook book;
  RelationCandidate c;
  c.relation.x(0) = std::nan("");
  c.relation.P.setIdentity();
  EXPECT_EQ(book.offer(1, c).verdict, RelationVerdict::kRejected);
  EXPECT_EQ(book.pendingCount(1), 0u);
}

}  // namespace
}  // namespace cvslam::merge
