#pragma once
// Brute-force descriptor matching with the thesis's criteria and DistRatio test (§4.2.6), and
// the scale-rate stability check (§4.2.7).
//
// p_k matches p_i iff d(i,k) is the smallest distance over the candidates and
// d(i,k) < DistRatio · (second smallest) — the test of Lowe's match.m that §4.2.6 adopts
// (DistRatio = 0.6 in §4.2.6; 0.4 in §5.10.2; 0.1–0.2 with stereo windows in §4.2.8).
// Optionally the match must also be mutual (i is k's best query among those that saw k).

#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/vision/descriptor_distance.h"
#include "cvslam/vision/features.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct MatchOptions {
  MatchNorm norm = MatchNorm::kLinf;  ///< linf | l2 | angle (ORB always uses Hamming)
  double dist_ratio = 0.6;            ///< DistRatio (§4.2.6)
  double max_distance = 0.0;          ///< absolute gate in the criterion's units; 0 = none
  bool mutual = true;                 ///< keep only mutual best matches
  /// A query with a single candidate has no second distance: accept it only when an
  /// absolute gate (max_distance > 0) is set and passed.
  bool accept_single_candidate = false;

  Status load(const ConfigNode& node);
};

struct Match {
  int query = -1;         ///< index in the query features
  int train = -1;         ///< index in the train features
  double distance = 0.0;  ///< best distance (criterion's units)
};

/// The norm actually used for a descriptor type (Hamming for ORB).
MatchNorm effectiveNorm(MatchNorm requested, DescriptorType type);

/// Matches every query feature against the train features given by `candidates[i]` (indices
/// into train), or against all train features when `candidates` is null.
std::vector<Match> matchDescriptors(const Features& query, const Features& train,
                                    const MatchOptions& options,
                                    const std::vector<std::vector<int>>* candidates = nullptr);

/// Candidate lists for matchDescriptors from predicted positions: train features within
/// `radius_px` of predicted[i] (e.g. the query's position mapped by the predicted motion, or a
/// landmark's predicted projection). Rows are sorted so the search is O(n log m + candidates).
std::vector<std::vector<int>> candidatesNear(const std::vector<cv::Point2f>& predicted,
                                             const Features& train, double radius_px);

/// Scale-rate stability (§4.2.7): correct matches share the scale ratio of the two views
/// (3 ± 0.14 for the thesis's 3:1 pair). Keeps matches with
/// |log2(rate / expected)| ≤ tolerance_log2, rate = size_train / size_query; expected ≤ 0
/// means "the median rate of the matches" (unknown zoom, frame to frame).
std::vector<Match> filterByScaleRate(const std::vector<Match>& matches, const Features& query,
                                     const Features& train, double expected, double tolerance_log2);

}  // namespace cvslam::vision
