#pragma once
// One stereo observation of a point feature, as the front end (or the feature-level
// simulator) hands it to the estimator (docs/conventions.md, docs/front_end.md; thesis eq. 5.20).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace cvslam {

/// How a feature relates to the map (thesis §6.3.2).
enum class ObservationType : uint8_t {
  kReobserved = 1,   ///< type 1: matches a landmark of this UAV's map (active or archived)
  kSeenByOther = 2,  ///< type 2: matches a landmark seen by another UAV (ground station)
  kNew = 3,          ///< type 3: not in any map yet
};

struct StereoObservation {
  uint32_t index = 0;                           ///< feature index: visual-word id, or the true
                                                ///< landmark id in feature-level simulation
  Eigen::Vector4d z = Eigen::Vector4d::Zero();  ///< [u_L v_L u_R v_R] [px], rectified images
  ObservationType type = ObservationType::kNew;
  int64_t landmark_id = -1;         ///< map landmark this was associated with, or −1
  std::vector<uint8_t> descriptor;  ///< raw descriptor bytes (may be empty)
  float response = 0.0f;            ///< detector response of the left keypoint (0: unknown)
};

/// All observations of one stereo epoch.
struct StereoFrameObservations {
  int64_t t_us = 0;  ///< dataset time [µs]
  std::vector<StereoObservation> observations;
};

}  // namespace cvslam
