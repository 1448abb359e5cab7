#pragma once
// The visual front end of one UAV (docs/front_end.md; thesis chapter 4): detect and describe both
// rectified images, match them under the stereo constraints (§4.2.8) — or, with the fast_sift
// detector, detect on the left image only, find each keypoint on the right by a search along
// its row (row_stereo_search.h) and describe only the matched ones — and turn every stereo
// match into a StereoObservation z = [u_L v_L u_R v_R] (eq. 5.20) whose index is the visual
// word of its left descriptor (feature index, §6.6.3). Every observation leaves as type 3
// (new); MapAssociator (map_association.h) marks the re-observed ones.

#include <memory>
#include <vector>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/vision/fast_sift.h"
#include "cvslam/vision/feature_detector.h"
#include "cvslam/vision/row_stereo_search.h"
#include "cvslam/vision/stereo_matcher.h"
#include "cvslam/vision/vocabulary.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct StereoFrontEndOptions {
  DetectorOptions detector;     ///< detector and its parameters
  StereoMatchOptions stereo;    ///< disparity window, VD band, criterion, DistRatio
  RowSearchOptions row_search;  ///< fast_sift: the right image searched along the row
  int max_observations = 0;     ///< keep the best (smallest descriptor distance) N; 0 = all

  Status load(const ConfigNode& node);
};

/// Intermediate results of the last process() call (for tests, tools and visualisation).
struct StereoFrontEndFrame {
  Features left;                  ///< fast_sift: the matched (and described) left keypoints only
  Features right;                 ///< fast_sift: the found right points, no descriptors
  std::size_t left_detected = 0;  ///< keypoints detected on the left
  std::vector<StereoMatch> matches;
};

/// Copies share the detector and its scratch buffers: one instance (create()) per thread.
class StereoFrontEnd {
 public:
  /// `vocabulary` may be null: the index is then 0. Its descriptor type must match the
  /// detector's.
  static Expected<StereoFrontEnd> create(const StereoFrontEndOptions& options,
                                         std::shared_ptr<const Vocabulary> vocabulary);

  /// Processes one rectified grey stereo pair into observations (type kNew, landmark −1).
  Status process(const cv::Mat& left, const cv::Mat& right,
                 std::vector<StereoObservation>* observations);

  const StereoFrontEndFrame& lastFrame() const { return frame_; }
  const StereoFrontEndOptions& options() const { return o_; }

 private:
  StereoFrontEnd() = default;
  Status matchDescribed(const cv::Mat& left, const cv::Mat& right);
  Status matchAlongRows(const cv::Mat& left, const cv::Mat& right);

  StereoFrontEndOptions o_;
  std::shared_ptr<FeatureDetector> detector_;  ///< all detectors but fast_sift
  std::shared_ptr<FastSift> fast_sift_;        ///< fast_sift
  std::shared_ptr<RowStereoSearch> row_search_;
  std::vector<cv::KeyPoint> detected_;  ///< fast_sift: all left keypoints
  std::vector<RowStereoMatch> row_matches_;
  std::shared_ptr<const Vocabulary> vocabulary_;
  StereoFrontEndFrame frame_;
};

}  // namespace cvslam::vision
