#pragma once
// Initialisation of new landmarks seen by one vehicle (step 5 of visual_inertial_slam.h;
// docs/conventions.md): the inverse observation model (stereo triangulation at the vehicle's
// pose, camera/stereo_camera.h) and proper augmentation of the joint state, P_LL = J_x P_vv J_xᵀ
// + J_z R J_zᵀ, P_Lx = J_x P_v· (CovarianceHelper::augment), at most max_new_landmarks_per_frame
// per frame, the nearest first (the best triangulated: disparity grows as 1/depth).
// Works on VariableKey::vehicle(i) of a state that may hold several vehicles: a new landmark is
// correlated with the rest of the state through that vehicle's rows only, and enters that
// vehicle's landmark book with its first estimate and OC yaw direction u_L = ∂p_L/∂x_v u_v.

#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/slam_options.h"

namespace cvslam {

class LinearisationOracle;

class LandmarkInitialiser {
 public:
  LandmarkInitialiser(const VariableKey& vehicle, const StereoCamera& camera,
                      const SlamOptions& options);

  /// Adds the frame's observations of landmarks neither in the state nor in `archive`
  /// (landmark_id < 0: a new landmark, named *next_fresh_id++) with a disparity of at least
  /// min_init_disparity_px, seen at t_us. Adds the number added to *initialised.
  Status initialise(SlamState& state, LandmarkBook& book, const LandmarkArchive& archive,
                    const StereoFrameObservations& frame, int64_t t_us, int64_t* next_fresh_id,
                    int* initialised) const {
    return initialise(state, book, archive, frame, t_us, next_fresh_id, initialised,
                      o_.max_new_landmarks_per_frame);
  }
  /// The same with at most `max_new` landmarks (the cooperation maps the points a peer's
  /// landmarks were matched to beyond the per-frame cap, dc_cooperation.h); `ids` (optional)
  /// gets, per observation of `frame`, the id of the landmark it created, or -1.
  Status initialise(SlamState& state, LandmarkBook& book, const LandmarkArchive& archive,
                    const StereoFrameObservations& frame, int64_t t_us, int64_t* next_fresh_id,
                    int* initialised, int max_new, std::vector<int64_t>* ids = nullptr) const;
  /// Where initialisation would put the landmark of `obs` and its marginal covariance
  /// J_x P_vv J_xᵀ + J_z R J_zᵀ, without adding it; false when it cannot be triangulated.
  bool triangulate(const SlamState& state, const StereoObservation& obs, Eigen::Vector3d* p_LinN,
                   Eigen::Matrix3d* covariance) const;
  /// Initialisation Jacobians at the truth (linearisation_oracle.h; simulation diagnostics).
  void setOracle(const LinearisationOracle* oracle) { oracle_ = oracle; }

 private:
  VariableKey vehicle_;
  StereoCamera camera_;
  SlamOptions o_;
  const LinearisationOracle* oracle_ = nullptr;
};

}  // namespace cvslam
