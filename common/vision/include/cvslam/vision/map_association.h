#pragma once
// Temporal association of the current stereo observations to the map (docs/front_end.md; thesis
// §5.5, §6.3.2): the estimator predicts each landmark's measurement ẑ = h(x̂) (eq. 5.20) with
// innovation covariance S = H P Hᵀ + R; an observation z is a candidate for landmark l when
//   (z − ẑ)ᵀ S⁻¹ (z − ẑ) ≤ γ  (Mahalanobis gate, χ²(4) quantile)
// and their descriptors are close. Among the candidates the smallest descriptor distance wins,
// with a DistRatio test when there are two or more (§4.2.6), one-to-one. Associated
// observations become type 1 (re-observed) with landmark_id set; the rest stay type 3 (new).
// Type 2 (seen by another UAV) is the ground station's to set.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/vision/descriptor_distance.h"
#include "cvslam/vision/features.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

/// One landmark as the estimator predicts it for the current epoch.
struct LandmarkPrediction {
  int64_t landmark_id = -1;
  Eigen::Vector4d z = Eigen::Vector4d::Zero();      ///< predicted [u_L v_L u_R v_R] [px]
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();  ///< innovation covariance [px²]
  std::vector<uint8_t> descriptor;                  ///< stored descriptor bytes
};

struct MapAssociationOptions {
  DescriptorType descriptor_type = DescriptorType::kSift;  ///< sift | orb
  MatchNorm norm = MatchNorm::kL2;                         ///< descriptor criterion (ORB: Hamming)
  double gate_chi2 = 13.28;                                ///< γ: χ²(4 dof) at 99 %
  double max_descriptor_distance = 250.0;  ///< absolute descriptor gate (criterion's units)
  double dist_ratio = 0.8;                 ///< DistRatio among gated candidates (§4.2.6)

  Status load(const ConfigNode& node);
};

struct AssociationStats {
  int candidates_gated = 0;  ///< (observation, landmark) pairs inside the Mahalanobis gate
  int associated = 0;        ///< observations marked type 1
};

/// Marks observations re-observed (type 1, landmark_id) where associated; the rest are set to
/// type 3 with landmark_id −1. Predictions with a non-invertible S are skipped.
Status associateToMap(const std::vector<LandmarkPrediction>& predictions,
                      const MapAssociationOptions& options,
                      std::vector<StereoObservation>* observations,
                      AssociationStats* stats = nullptr);

}  // namespace cvslam::vision
