#pragma once
// One agent's image path into its VSLAM filter (docs/architecture.md, docs/front_end.md; thesis
// §5.10): a rectified stereo pair goes through the visual front end (chapter 4: detection, stereo
// matching under the disparity window), the map predicts its landmarks' observations
// (map_prediction.h), the observations are associated to them by descriptor and Mahalanobis gate
// (§5.5, §6.3.2: type 1 re-observed / type 3 new), and the frame is processed by
// VisualInertialSlam. No transport, no simulation: cvslam_run feeds it rendered images, the agent
// process will feed it images received over LCM.
//
// New landmarks are confirmed frame to frame first: a stereo match that is not a map landmark
// is offered to the filter for initialisation only when the previous frame had a stereo match
// with a close descriptor whose triangulated point, carried by the filter's motion estimate,
// projects within `confirm_gate_px` of it in both images (so its disparity agrees too). A
// wrong stereo match — whose triangulated depth is wrong, and which the filter's nearest-first
// initialisation would otherwise favour when its disparity is too large — is rarely confirmed.
//
// Loop detection by appearance (appearance_loop_detector.h, thesis §5.5.2): every frame the
// unassociated observations are matched against the archive by feature index and
// descriptor; together with the observations the projection gate associated to loop
// landmarks (archived, unseen for slam.loop_closure_min_age_s) they are verified by a robust
// rigid fit and a bound on the vehicle's correction. The verified ones are re-observations
// (type 1) of the archived landmarks, and the filter's loop-closing path closes the loop;
// gated loop associations that fail the verification are undone (type 3). Needs a
// vocabulary (the feature index).
//
// Landmark ids: an associated observation carries its landmark's id; a confirmed new one gets
// a fresh id from this pipeline, so that the caller learns which observations the filter
// initialised as landmarks (VisualFrameResult::initialised) — e.g. to attach ground truth.
// Unconfirmed observations (landmark_id −1) are not given to the filter.
//
// YAML (agent.yaml section `frontend:`): the StereoFrontEndOptions keys (`detector`,
// `stereo`, `max_observations`, see config/front_end.yaml) plus `association:`
// (MapAssociationOptions), `prediction:` (MapPredictionOptions), `max_hamming_distance`,
// `vocabulary`, `loop_detection:` (LoopDetectionOptions). The stereo focal length and baseline
// always come from the camera.

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/slam/appearance_loop_detector.h"
#include "cvslam/slam/map_prediction.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "cvslam/vision/map_association.h"
#include "cvslam/vision/stereo_front_end.h"
#include "cvslam/vision/vocabulary.h"

namespace cvslam {

class ConfigNode;

/// Which confirmed new points the filter is offered first (VisualFrontEndOptions).
enum class NewLandmarkOrder {
  kResponse,      ///< the detector's strongest keypoints first
  kConfirmation,  ///< the smallest frame-to-frame confirmation residual first
};

struct VisualFrontEndOptions {
  vision::StereoFrontEndOptions front_end;    ///< detector, stereo, max_observations
  vision::MapAssociationOptions association;  ///< `association:` (descriptor type follows the
                                              ///< detector)
  MapPredictionOptions prediction;            ///< `prediction:`
  /// Association's absolute descriptor gate for ORB (Hamming bits); SIFT uses
  /// association.max_descriptor_distance.
  double max_hamming_distance = 50.0;
  bool confirm_new = true;       ///< frame-to-frame confirmation of new landmarks (above)
  double confirm_gate_px = 6.0;  ///< max |z − ẑ| per coordinate for a confirmation [px]
  /// Vocabulary files for the feature index (§6.6.3), relative to the config file; empty: none
  /// (index 0). `vocabulary` serves the SIFT detectors (adaptive_sift, sift), `vocabulary_orb`
  /// the ORB detector; each must hold descriptors of its detector's type.
  std::string vocabulary;
  std::string vocabulary_orb;
  /// New landmarks are offered only to fill the map up to this many landmarks of the state
  /// re-observed in the frame (0: the map's k, thesis §5.8). A landmark is worth most while
  /// it is tracked: initialising new ones beyond what the k-nearest map keeps would push
  /// still-visible landmarks into the archive after two or three frames (docs/front_end.md).
  int tracked_landmarks = 0;
  /// The order in which confirmed new points are offered (as many as the map has room for).
  /// `confirmation`: the points that confirmed best, a choice that depends on the view.
  /// `response`: the scene's most distinctive points, which another UAV flying over the same
  /// ground detects and maps too: 3–4× more cross-UAV landmark pairs for DC to find, but
  /// less accurate alone on the recordings and on thesis_loop's UAV2 (docs/front_end.md
  /// "New landmarks by detector response"), hence not the default.
  NewLandmarkOrder new_landmark_order = NewLandmarkOrder::kConfirmation;
  /// With `response`: the image is cut into this many cells per side and the strongest point
  /// of every cell is offered before the second strongest of any, so that the new landmarks
  /// spread over the view (1: the strongest wherever they are).
  int new_landmark_grid = 4;
  /// Keep one observation per left pixel (SIFT gives one keypoint per dominant orientation,
  /// i.e. the same point twice with different descriptors). Off by default: on thesis_loop it
  /// changed the drift by several metres either way (docs/front_end.md).
  bool drop_duplicate_points = false;
  LoopDetectionOptions loop_detection;  ///< `loop_detection:` (appearance_loop_detector.h)
  /// Overrides slam.first_estimate_jacobians when this front end feeds the filter (absent:
  /// the slam setting). The landmark-only first-estimate Jacobians help at feature level
  /// but, with real keypoints, let the filter gain spurious yaw information (UAV2 of
  /// thesis_loop, 60 s: yaw error 0.9° and ATE 1.22 m with them, 0.17° and 0.25 m without;
  /// docs/front_end.md).
  std::optional<bool> first_estimate_jacobians;
  /// Overrides slam.observability_constrained likewise. Measured on the full thesis_loop with
  /// images (seed 2010): with it UAV1 missed its loop closure (ATE 20.0 m, NEES ≈ 1.4e4; with
  /// FEJ too 29.7 m), without it UAV1 2.96 m with the loop closed at 199 s, NEES 5.8
  /// (docs/front_end.md). Why the constraint hurts with real keypoints is open.
  std::optional<bool> observability_constrained;
  /// Overrides slam.second_order_noise likewise. With real keypoints the assumed pixel σ is
  /// already several times their re-observation error, and the term only slowed the
  /// map on the recordings (docs/results/ideal_ekf.md "Second-order noise").
  std::optional<bool> second_order_noise;
  /// Overrides slam.second_order_mean likewise. Not measured to help with real keypoints: on
  /// team3_aerial its first, additive version left the NEES and errors where they were and
  /// halved the pairs DC fused on seed 41 (docs/filter.md "The second-order mean").
  std::optional<bool> second_order_mean;
  /// Overrides slam.pixel_sigma likewise (absent: the slam setting). The slam value is the
  /// feature-level simulator's true noise; detected keypoints are localised several times
  /// tighter (re-observation error 0.07-0.09 px rendered, stereo row error 0.14 px median on
  /// real EuRoC pairs), and the filter fed them with 0.5 px ran below its NEES band
  /// (docs/front_end.md "Pixel σ of keypoints").
  std::optional<double> pixel_sigma;

  Status load(const ConfigNode& node);
  /// `slam` as the filter runs it behind this image path: each override above that is set
  /// replaces its slam key.
  SlamOptions resolve(SlamOptions slam) const;
};

/// What one stereo pair did.
struct VisualFrameResult {
  StereoFrameObservations frame;  ///< observations as given to the filter (ids set)
  FrameReport report;
  int predictions = 0;  ///< landmarks predicted in view
  int confirmed = 0;    ///< new observations confirmed frame to frame
  int duplicates = 0;   ///< observations dropped as a second keypoint of the same point
  vision::AssociationStats association;  ///< gate candidates and type-1 observations
  LoopDetection loop;                    ///< the archive query, if one ran
  std::vector<std::pair<std::size_t, int64_t>> initialised;  ///< (observation, new landmark)
  double front_end_ms = 0.0;          ///< detection, description, stereo matching [ms]
  vision::FrontEndTimings front_end;  ///< front_end_ms by stage
  int prioritised = 0;          ///< observations kept under max_observations for a priority region
  double association_ms = 0.0;  ///< prediction and association [ms]
  double filter_ms = 0.0;       ///< VisualInertialSlam::processFrame [ms]
};

/// Loads the feature-index vocabulary of the configured detector (`vocabulary` or
/// `vocabulary_orb`; relative paths are taken from `config_dir`). Null when that key is empty;
/// an error when the file is missing, malformed or of the other descriptor type — agents must
/// never silently fall back to index 0, or they would not find shared landmarks.
Expected<std::shared_ptr<const vision::Vocabulary>> loadFeatureIndexVocabulary(
    const VisualFrontEndOptions& options, const std::string& config_dir);

class VisualSlamPipeline {
 public:
  /// `vocabulary` may be null (feature index 0).
  static Expected<VisualSlamPipeline> create(const VisualFrontEndOptions& options,
                                             const StereoCamera& camera,
                                             std::shared_ptr<const vision::Vocabulary> vocabulary);

  /// Runs front end → prediction → association → filter for the pair taken at t_us.
  Status process(int64_t t_us, const cv::Mat& left, const cv::Mat& right, VisualInertialSlam& slam,
                 VisualFrameResult* result);

  const vision::StereoFrontEnd& frontEnd() const { return front_end_; }
  const VisualFrontEndOptions& options() const { return o_; }

 private:
  VisualSlamPipeline(VisualFrontEndOptions o, vision::StereoFrontEnd fe, bool feature_index)
      : o_(std::move(o)),
        front_end_(std::move(fe)),
        loop_detector_(o_.loop_detection),
        feature_index_(feature_index) {}

  /// Queries the archive by appearance and marks the verified loop observations (type 1).
  void detectLoop(int64_t t_us, const VisualInertialSlam& slam, VisualFrameResult* result);
  /// Distance used to compare descriptors (Hamming for ORB).
  vision::MatchNorm descriptorNorm() const;

  /// Marks the unassociated observations confirmed by the previous frame (fresh ids).
  void confirmNew(const VisualInertialSlam& slam, std::vector<StereoObservation>* observations,
                  int* confirmed);
  /// expected_, ahead_: where the previous frame's unmapped points project at the filter's
  /// current pose (once per frame, for the priority regions and the confirmation).
  void expectPrevious(const VisualInertialSlam& slam);
  /// priority_: where the map predicts a landmark (association gate) and where the previous
  /// frame's unmapped points are expected (confirmation gate), for the front end's cap.
  void priorityRegions();
  /// Keeps this frame's unmapped stereo matches, triangulated, for the next confirmation.
  void rememberUnmapped(const VisualInertialSlam& slam, const VisualFrameResult& result);

  struct PreviousPoint {
    Eigen::Vector3d p_LinN;
    const std::vector<uint8_t>* descriptor;  // into previous_observations_
  };

  VisualFrontEndOptions o_;
  std::vector<StereoObservation> previous_observations_;
  std::vector<PreviousPoint> previous_;
  StereoFrameObservations filter_frame_;   // what the filter gets (reused)
  std::vector<std::size_t> filter_index_;  // filter_frame_ observation -> result observation
  vision::StereoFrontEnd front_end_;
  std::vector<PredictedObservation> predicted_;    // reused every frame
  std::vector<vision::LandmarkPrediction> gated_;  // reused every frame
  std::vector<vision::PriorityRegion> priority_;   // reused every frame
  std::vector<Eigen::Vector4d> expected_;          // previous_ projected now (expectPrevious)
  std::vector<bool> ahead_;                        // … in front of the camera
  AppearanceLoopDetector loop_detector_;
  bool feature_index_ = false;          // observations carry visual words (a vocabulary is loaded)
  bool measurement_model_set_ = false;  // the filter took this path's overrides (process)
  int64_t frames_ = 0;
  int64_t next_landmark_id_ = 0;
};

}  // namespace cvslam
