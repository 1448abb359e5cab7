#pragma once
// Appearance-based loop detection (thesis §5.5.2 loop closing; docs/conventions.md feature index).
//
// The projection-gated association (map_prediction.h, map_association.h) proposes archived
// landmarks only where the filter predicts them. After a long excursion the vehicle may be
// many σ away from the truth, the old landmarks are predicted metres from where they appear,
// and the loop is never proposed. This detector looks for it by appearance instead:
//   1. candidates: each unassociated observation is compared with the archived landmarks of
//      its own feature index (visual word; the archive's inverted index), old enough to be
//      a loop (last seen ≥ min_last_seen_age, archived ≥ min_archived_age) and within the
//      search radius of where the observation triangulates now; the closest stored descriptor
//      wins if it passes the absolute gate and the DistRatio test (§4.2.6). Words with more
//      than max_word_landmarks landmarks are not distinctive and skipped (stop words).
//   2. geometric verification: RANSAC over pairs of candidates of the rigid yaw +
//      translation (loop_alignment.h) that moves the points as the cameras triangulate them
//      now (current estimate) onto the archived positions; the largest consensus set within
//      inlier_distance_m is refitted and accepted when it has ≥ min_inliers members, its RMS
//      residual is ≤ max_rms_m, |yaw| ≤ max_yaw_deg and the vehicle's correction is within
//      max_correction_sigmas σ. Observations that the projection gate already associated to
//      loop landmarks are candidates too (they pass the same verification: a look-alike
//      place inside a wide archived-landmark gate is not a loop).
// The search radius comes from the filter's own uncertainty, generously scaled (the filter is
// over-confident after a long excursion): search_sigma_scale × the largest horizontal
// position σ, at least min_search_radius_m and at most max_offset_m. Appearance and rigid
// geometry alone cannot tell a place from another one that looks the same (repetitive
// ground; the rendered aerial world reuses a few texture tiles every ≈20 m), so the
// position prior is what rejects a look-alike place far from where the vehicle can be.
// The accepted observations are then handed to VisualInertialSlam as re-observations of the
// archived landmarks, whose loop-closing path (alignLoop, iterated update with a joint NIS gate;
// slam options loop_closure_*) closes the loop.
//
// YAML (section `frontend.loop_detection:`): the LoopDetectionOptions keys.

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/loop_alignment.h"
#include "cvslam/vision/descriptor_distance.h"

namespace cvslam {

class ConfigNode;

struct LoopDetectionOptions {
  bool enabled = true;
  /// Query the archive every this many frames (1: every frame). The query is cheap (word
  /// buckets of a few landmarks), but this bounds its cost on slow machines.
  int every_n_frames = 1;
  double max_descriptor_distance = 250.0;  ///< absolute gate (L2 bytes for SIFT, bits for ORB)
  double dist_ratio = 0.8;                 ///< DistRatio among the word's candidates (§4.2.6)
  int max_word_landmarks = 64;             ///< larger word buckets are skipped (stop words)
  /// Search radius around where an observation triangulates now (above): this many times
  /// the largest horizontal position σ of the vehicle, clamped to [min_search_radius_m,
  /// max_offset_m] [m].
  double search_sigma_scale = 10.0;
  double min_search_radius_m = 5.0;
  double max_offset_m = 60.0;  ///< the largest drift a loop closure may correct [m]
  /// The fitted horizontal correction of the vehicle may be at most this many times its
  /// largest horizontal position σ (or min_search_radius_m, if larger).
  double max_correction_sigmas = 3.5;
  int ransac_iterations = 200;     ///< random candidate pairs tried (all pairs if fewer)
  double inlier_distance_m = 0.3;  ///< residual of an inlier after the rigid fit [m]
  int min_inliers = 6;             ///< verified matches needed to report a loop
  double max_rms_m = 0.2;          ///< RMS residual of the refitted consensus set [m]
  double max_yaw_deg = 20.0;       ///< largest accepted yaw correction [deg]
  /// Smallest separation of a RANSAC pair's observed points [m]: closer points fix no yaw.
  double min_pair_separation_m = 0.5;

  Status load(const ConfigNode& node);
};

/// One query's outcome.
struct LoopDetection {
  int candidates = 0;  ///< observation → archived landmark matches passing the descriptor tests
  int inliers = 0;     ///< of the best consensus set
  bool detected = false;
  LoopAlignment alignment;  ///< observed (current estimate) → archived positions
  /// (observation index, archived landmark id) of the verified matches (when detected).
  std::vector<std::pair<std::size_t, int64_t>> matches;
};

/// What the archive query needs besides the observations.
struct LoopQuery {
  int64_t t_us = 0;                   ///< frame time
  EstimatedPose x_v;                  ///< current vehicle estimate
  double min_last_seen_age_s = 30.0;  ///< loop landmarks: unseen for at least this [s]
  double min_archived_age_s = 10.0;   ///< and archived at least this long ago [s]
  vision::MatchNorm norm = vision::MatchNorm::kL2;  ///< descriptor distance (kHamming for ORB)
  /// Largest horizontal position σ of the vehicle [m] (sets the search radius).
  double position_sigma_m = 0.0;
};

class AppearanceLoopDetector {
 public:
  explicit AppearanceLoopDetector(const LoopDetectionOptions& options = {}) : o_(options) {}
  const LoopDetectionOptions& options() const { return o_; }
  /// Search radius for a vehicle with this horizontal position σ [m].
  double searchRadius(double position_sigma_m) const;

  /// Matches the observations with landmark_id < 0 against the archive, adds those already
  /// associated to loop landmarks, and verifies them geometrically (above). Observations
  /// are not modified. Deterministic.
  LoopDetection detect(const std::vector<StereoObservation>& observations,
                       const StereoCamera& camera, const LandmarkArchive& archive,
                       const LoopQuery& query) const;

 private:
  LoopDetectionOptions o_;
};

}  // namespace cvslam
