#pragma once
// Dynamic initialisation: a start without ground truth for a vehicle that is already moving
// when its data begins (no rest period for ins/static_initializer.h).
//
// Stereo gives metric 3-D points in every frame, so the camera's motion over a short window is
// known with its scale: the previous frame's tracked points, triangulated
// (StereoCamera::triangulateInCamera), and their pixels in the current left image give the
// relative pose by RANSAC PnP (EPnP, then Levenberg–Marquardt on the inliers: the pixels are
// precise where stereo depth is not), chained into the poses of the body B_k in the first
// body frame B_0 through the camera extrinsics. The IMU between frames k and k+1, integrated in B_k
// with the gyro (α_k = ∬ ΔR f, β_k = ∫ ΔR f), then ties velocities and gravity to those poses
// linearly:
//     p_{k+1} − p_k = v_k Δt + ½ g Δt² + R_k α_k,      v_{k+1} − v_k = g Δt + R_k β_k,
// all in B_0 (the visual-inertial alignment of VINS-Mono, with the scale known from stereo).
// The gyro bias comes first, from the visual rotations (Gauss–Newton on Log(ΔR_gyroᵀ ΔR_vis)),
// and corrects the integration: real turn-on biases (EuRoC: 0.08 rad/s) would otherwise
// rotate α and β by several degrees over the window.
// Least squares gives v_0..v_K and g; |g| must be the local gravity within
// max_gravity_error. The estimator's frame N is then gravity-aligned NED with yaw 0 and origin
// at the body's position at the last frame (the initialisation time), as after a static
// start. The accelerometer bias keeps its prior: at this window length it is not separable
// from a tilt (σ_tilt ≈ σ_ba / g), which the reported tilt σ includes.
//
// Tracks: observations with descriptors (SIFT: 128 bytes, ORB: 32) are matched to the previous
// frame's (descriptor distance, ratio test, within match_radius_px of their position: frames
// are 1/20 s apart); without descriptors (feature-level simulation) by equal feature index.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/features.h"

namespace cvslam {

class ConfigNode;

/// `agent.dynamic_init` of agent.yaml (cvslam_agent, `agent.start: auto` when the vehicle is
/// not at rest).
struct DynamicInitializerOptions {
  double window_s = 1.0;               ///< frames spanning this long are aligned [s]
  int min_tracks = 12;                 ///< 3-D matches needed between consecutive frames
  int ransac_iterations = 100;         ///< PnP RANSAC iterations per frame pair
  double reprojection_error_px = 2.0;  ///< PnP RANSAC inlier threshold [px]
  double max_depth = 30.0;             ///< farther points (depth ∝ 1/disparity) are not used [m]
  double match_radius_px = 40.0;       ///< a track's next observation lies within this [px]
  double max_gravity_error = 0.5;      ///< |g| solved may differ from gravity by this [m/s²]
  double tilt_sigma_min = 0.02;        ///< floor of the reported roll/pitch 1σ [rad]
  double velocity_sigma_min = 0.05;    ///< floor of the reported velocity 1σ [m/s]
  /// Floor of the reported gyro-bias 1σ [rad/s]: the fit's own σ treats the frame pairs as
  /// independent, which chained visual rotations are not (errors of 3–4 of its σ seen on the
  /// EuRoC MH_01 flight at feature level).
  double gyro_bias_sigma_min = 0.005;
  /// A frame at most this long after the last IMU sample is reached by holding that sample
  /// (zero-order hold, as VehiclePropagation does): camera and IMU need not be stamped on one
  /// grid, and in lockstep the sample after a frame arrives only once the frame is processed.
  /// Longer, the IMU does not cover the frames [s].
  double max_imu_hold_s = 0.02;
  vision::MatchOptions matching;  ///< descriptor matching between consecutive frames

  Status load(const ConfigNode& node);
};

/// The vehicle state found in motion, in the estimator's gravity-aligned NED frame.
struct DynamicInitialization {
  int64_t t_us = 0;  ///< time of the last frame of the window
  Eigen::Quaterniond q_BtoN = Eigen::Quaterniond::Identity();  ///< yaw 0
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();               ///< [m/s]
  /// Gyro bias making the gyro agree with the visual rotations over the window [rad/s].
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_sigma = Eigen::Vector3d::Zero();  ///< its 1σ [rad/s]
  double tilt_sigma = 0.0;                                    ///< 1σ of roll and pitch [rad]
  double velocity_sigma = 0.0;                                ///< 1σ per velocity axis [m/s]
  double gravity_norm = 0.0;                                  ///< |g| of the free solution [m/s²]
  int frames = 0;                                             ///< frames aligned
  int min_inliers = 0;  ///< fewest PnP inliers of a frame pair
};

class DynamicInitializer {
 public:
  DynamicInitializer(const DynamicInitializerOptions& options, const StereoCamera& camera,
                     double gravity);

  /// IMU samples in time order (before and between the frames).
  void addImu(const ImuSample& sample);
  /// A frame's stereo observations. A frame that cannot be tracked from the previous one
  /// (too few matches or inliers) restarts the window at it.
  void addFrame(const StereoFrameObservations& frame);
  /// The window spans window_s.
  bool ready() const;
  /// Solves the alignment over the window; fails with one line saying why.
  Expected<DynamicInitialization> solve() const;
  int frames() const { return static_cast<int>(frames_.size()); }

 private:
  struct Frame {
    int64_t t_us = 0;
    std::vector<StereoObservation> observations;
    std::vector<Eigen::Vector3d> p_inC;  // triangulated, per observation (NaN: failed)
    Eigen::Matrix3d R_C0toCk = Eigen::Matrix3d::Identity();  // camera k in camera 0: R_{C0←Ck}
    Eigen::Vector3d p_CkinC0 = Eigen::Vector3d::Zero();
    int inliers = 0;  // of the fit to the previous frame
  };
  /// Pairs (previous observation, current observation) of the same point.
  std::vector<std::pair<int, int>> track(const Frame& previous, const Frame& current) const;
  /// Motion of the camera, p_prev = R p_cur + t, from the previous frame's points and their
  /// pixels in the current left image; false if too few inliers.
  bool fitMotion(const std::vector<Eigen::Vector3d>& prev,
                 const std::vector<Eigen::Vector2d>& cur_px, Eigen::Matrix3d* R, Eigen::Vector3d* t,
                 int* inliers) const;
  /// The IMU samples spanning [t0, t1], interpolated at both ends.
  std::vector<ImuSample> samplesBetween(int64_t t0, int64_t t1) const;
  /// ΔR of the bias-corrected gyro over [t0, t1] (body at t1 in body at t0).
  Eigen::Matrix3d integrateRotation(int64_t t0, int64_t t1, const Eigen::Vector3d& gyro_bias) const;
  /// α and β of the IMU between two times, in the body frame at t0 (gyro-rotated).
  void preintegrate(int64_t t0, int64_t t1, const Eigen::Vector3d& gyro_bias,
                    Eigen::Vector3d* alpha, Eigen::Vector3d* beta) const;
  /// Gyro bias that makes the integrated gyro agree with the visual rotations, with its 1σ.
  Eigen::Vector3d gyroBias(const std::vector<Eigen::Matrix3d>& R_B0toBk,
                           Eigen::Vector3d* sigma) const;

  DynamicInitializerOptions o_;
  StereoCamera camera_;
  double gravity_;
  std::vector<ImuSample> imu_;
  std::vector<Frame> frames_;
};

}  // namespace cvslam
