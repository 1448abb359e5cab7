#pragma once
// Innovation test over time of one peer's shared estimates ("CI that is told the
// truth"). Every exchange gives the normalised innovation squared of the peer's landmarks
// against the local ones, NIS = dᵀ S⁻¹ d with a covariance S that BOUNDS the true one (so the
// NIS of a consistent peer is at most χ²(dof)-distributed). Over a window of exchanges,
// Σ NIS above the χ²(Σ dof) quantile at `probability` means the peer reports covariances
// smaller than its errors: its estimates are then down-weighted, R scaled by Σ NIS / Σ dof (the
// factor that would make the window's mean NIS equal to its dof), until the window is
// consistent again. Counted by the caller (DcCooperationStatistics::peer_down_weighted).

#include <deque>

namespace cvslam::coop {

struct PeerConsistencyOptions {
  int window = 10;             ///< exchanges in the test; 0 disables it
  double probability = 0.999;  ///< χ² quantile of Σ NIS over the window
};

class PeerConsistency {
 public:
  explicit PeerConsistency(const PeerConsistencyOptions& options = {}) : o_(options) {}

  /// Adds one exchange (nis ≥ 0 with dof > 0 degrees of freedom); returns scale().
  double add(double nis, int dof);
  /// Scale for the peer's R: 1 while the window is consistent, Σ NIS / Σ dof (> 1) otherwise.
  double scale() const;

 private:
  struct Exchange {
    double nis;
    int dof;
  };
  PeerConsistencyOptions o_;
  std::deque<Exchange> window_;
};

}  // namespace cvslam::coop
