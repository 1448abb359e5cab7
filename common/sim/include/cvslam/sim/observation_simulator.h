#pragma once
// Feature-level stereo observations (thesis §5.4 eq. 5.20, §5.9): every landmark visible in
// both images of the StereoCamera gives a StereoObservation with index = true landmark id and
// z = projected pixels + pixel noise. Visibility is decided on the true projection (no terrain
// occlusion). Noise kinds (noise_model.h), per component of z = [u_L v_L u_R v_R]:
//   gaussian              n ~ N(0, σ²) independently per component
//   non_gaussian_centred  zero mean, std σ, uniform or heavy-tailed mixture (`shape`)
//   non_centred           n = bias_px + N(0, σ²): a constant offset per component for the
//                         whole run. The default offset [0.5 0.5 0 0.5] px shifts the left
//                         image only in u, i.e. biases the disparity and hence the range, the
//                         weak direction of stereo the thesis points at (§5.9, Table 5.4).
// Outliers (rate `outlier_rate`): z replaced by a random stereo match — u_L, v uniform in the
// image, disparity uniform in [0, fx·b/min_depth], v_R = v_L. Feature cap: keep the
// `max_features` nearest (by distance to the left camera) or a random subset. Observations are
// returned sorted by id. Deterministic given the seed.

#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/random.h"
#include "cvslam/core/status.h"
#include "cvslam/scenario/noise_model.h"
#include "cvslam/scenario/pixel_noise_options.h"
#include "cvslam/scenario/trajectory.h"
#include "cvslam/scenario/world.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

class ObservationSimulator {
 public:
  ObservationSimulator(const StereoCameraOptions& camera, const PixelNoiseOptions& options,
                       uint64_t seed);

  /// Observations of `world` from the true vehicle state at dataset time t_us.
  StereoFrameObservations observe(int64_t t_us, const TrajectoryState& state, const World& world);

  const StereoCamera& camera() const { return camera_; }
  const PixelNoiseOptions& options() const { return o_; }

 private:
  Eigen::AlignedBox2d searchBox(const Eigen::Vector3d& p_CinN, const Eigen::Matrix3d& R_CtoN,
                                const World& world) const;

  StereoCamera camera_;
  PixelNoiseOptions o_;
  Rng rng_;
  struct Candidate {
    uint32_t id;
    double range;
    Eigen::Vector3d p_LinC;
  };
  std::vector<Candidate> scratch_;  // reused between frames
};

}  // namespace cvslam::sim
