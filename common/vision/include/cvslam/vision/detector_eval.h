#pragma once
// Detector and descriptor evaluation in the thesis's terms (§4.4.5–4.4.7; tools/
// cvslam_detector_eval, tests/swif):
//  - repeatability (§4.4.5): the share of the features of one view that the detector finds again
//    in the other, within `eps` pixels after the known homography, among the features that both
//    views can see (Schmid/Mikolajczyk's definition, which the thesis's figures use);
//  - matching: number of good matches (NGM), precision NGM / matches and the matching score
//    MS = NGM / NEF (§4.4.7.2 i), with "good" from the known homography, from a fundamental
//    matrix fitted by RANSAC (real consecutive frames), or from the epipolar constraint of a
//    rectified stereo pair.

#include <opencv2/core.hpp>
#include <vector>

#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/features.h"

namespace cvslam::vision {

struct RepeatabilityResult {
  int visible_a = 0;           ///< features of view a that map inside view b
  int visible_b = 0;           ///< features of view b that map inside view a
  int correspondences = 0;     ///< one-to-one pairs within eps
  double repeatability = 0.0;  ///< correspondences / min(visible_a, visible_b)
};

/// Repeatability of keypoints `a` (image `size_a`) and `b` (image `size_b`) under H (a → b).
RepeatabilityResult repeatability(const std::vector<cv::KeyPoint>& a, cv::Size size_a,
                                  const std::vector<cv::KeyPoint>& b, cv::Size size_b,
                                  const cv::Matx33d& H_ab, double eps_px);

struct MatchQuality {
  int features = 0;             ///< NEF: min(features of a, features of b)
  int matches = 0;              ///< matches returned by the matcher
  int correct = 0;              ///< NGM
  double precision = 0.0;       ///< NGM / matches
  double matching_score = 0.0;  ///< MS = NGM / NEF
};

/// Good match: ‖H p_a − p_b‖ ≤ eps.
MatchQuality matchQualityHomography(const Features& a, const Features& b,
                                    const std::vector<Match>& matches, const cv::Matx33d& H_ab,
                                    double eps_px);
/// Good match: inlier of a fundamental matrix fitted by RANSAC (OpenCV FM_RANSAC, `eps_px` from
/// the epipolar line, confidence 0.999). Fewer than 8 matches: none is counted good.
MatchQuality matchQualityFundamental(const Features& a, const Features& b,
                                     const std::vector<Match>& matches, double eps_px);
/// Rectified stereo pair (a = left): good match iff |v_a − v_b| ≤ eps and the disparity
/// u_a − u_b is in [min_disparity, max_disparity].
MatchQuality matchQualityStereo(const Features& a, const Features& b,
                                const std::vector<Match>& matches, double eps_px,
                                double min_disparity, double max_disparity);

}  // namespace cvslam::vision
