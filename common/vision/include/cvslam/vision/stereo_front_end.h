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
  /// Keep the best N stereo matches (0 = all): those in a priority region first, then by match
  /// quality (fast_sift: detector.fast_sift.describe_budget too).
  int max_observations = 0;

  Status load(const ConfigNode& node);
};

/// A box of the left image where a keypoint is wanted: around a landmark the map predicts, or a
/// point of the previous frame still to be confirmed (visual_slam_pipeline.h). Under
/// max_observations the matches inside a region are kept before all others, so that the
/// observations the association and the confirmation will look for are the ones described.
struct PriorityRegion {
  cv::Point2f center;     ///< predicted left pixel [px]
  cv::Point2f half_size;  ///< half width and height of the box [px]
};

/// Where the time of one process() call went [ms].
struct FrontEndTimings {
  double detect_ms = 0.0;    ///< scale space and keypoints (both images unless fast_sift)
  double stereo_ms = 0.0;    ///< stereo matching, or fast_sift's row search
  double describe_ms = 0.0;  ///< fast_sift: orientations and descriptors of the kept matches
  double index_ms = 0.0;     ///< visual words (feature index) and observation assembly
};

/// Intermediate results of the last process() call (for tests, tools and visualisation).
struct StereoFrontEndFrame {
  Features left;                  ///< fast_sift: the matched (and described) left keypoints only
  Features right;                 ///< fast_sift: the found right points, no descriptors
  std::size_t left_detected = 0;  ///< keypoints detected on the left
  std::vector<StereoMatch> matches;
  int prioritised = 0;  ///< kept matches that lay in a priority region
  FrontEndTimings timings;
};

/// Copies share the detector and its scratch buffers: one instance (create()) per thread.
class StereoFrontEnd {
 public:
  /// `vocabulary` may be null: the index is then 0. Its descriptor type must match the
  /// detector's.
  static Expected<StereoFrontEnd> create(const StereoFrontEndOptions& options,
                                         std::shared_ptr<const Vocabulary> vocabulary);

  /// Processes one rectified grey stereo pair into observations (type kNew, landmark −1).
  /// `priority` (may be null) decides which matches max_observations (or fast_sift's
  /// describe_budget) keeps first.
  Status process(const cv::Mat& left, const cv::Mat& right,
                 std::vector<StereoObservation>* observations,
                 const std::vector<PriorityRegion>* priority = nullptr);

  const StereoFrontEndFrame& lastFrame() const { return frame_; }
  const StereoFrontEndOptions& options() const { return o_; }
  /// How many matches a frame keeps (max_observations, or fast_sift's describe_budget; 0 = all).
  int keptMatches() const;

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
  /// Marks the priority regions on a coarse grid of the left image (mask_).
  void markPriority(cv::Size image, const std::vector<PriorityRegion>* priority);
  bool prioritised(const cv::Point2f& left_px) const;
  /// order_: the `cap` of `n` items kept, prioritised before the rest, each group by
  /// `better`.
  template <typename Better>
  void rank(std::size_t n, const std::vector<cv::Point2f>& left_px, int cap, Better better);

  std::vector<uint8_t> mask_;  ///< priority mask, one cell per kMaskCell² pixels
  int mask_cols_ = 0, mask_rows_ = 0;
  std::vector<cv::Point2f> rank_px_;
  std::vector<std::size_t> order_;
  std::vector<uint8_t> rank_in_region_;
  std::shared_ptr<const Vocabulary> vocabulary_;
  StereoFrontEndFrame frame_;
};

}  // namespace cvslam::vision
