#pragma once
// Observability-constrained EKF (OC-EKF; Huang, Mourikis & Roumeliotis 2010; Hesch et al.
// 2014, "Consistency analysis and improvement of vision-aided inertial navigation") for the
// stereo-inertial SLAM of visual_inertial_slam.h.
//
// Without an absolute reference, four directions of the joint state are unobservable: the
// global translation and the global yaw (rotation about the NED z axis; roll and pitch are
// observable through gravity). With body-frame velocity and ZYX Euler angles (docs/conventions.md)
// a global yaw rotation δψ moves the state along
//   vehicle   u_v = [e3 × p | 0 (v_B) | 0 0 1 (φ θ ψ) | 0 (biases)],   landmark  u_L = e3 × p_L.
// An EKF linearised at estimates that change between propagation and update (each update
// moves p and p_L) sees a slightly different u at every step, so the observations appear to
// inform the yaw: the yaw variance shrinks below its initial value and the filter becomes
// over-confident while the trajectory drifts. (Measured on thesis_loop: yaw σ 1° → 0.27°
// while the yaw error grew to 3.7°.)
// The remedy: carry u along the filter's own transition (u_v ← Φ u_v at propagation, u_L ←
// ∂p_L/∂x_v u_v at initialisation) and project every observation Jacobian onto the
// complement of span{translation, u}: the smallest change with H N = 0, with the attitude
// columns weighted by the landmark's range (SlamOptions::oc_projection; docs/filter.md).
// The translation directions are already in the null space of the stereo Jacobian (it
// depends on p_L − p), and the INS transition maps them onto themselves. The vehicle's u_v
// comes from the vehicle model (filter/vehicle_model.h: vehicle_model::yawDirection).

#include <Eigen/Core>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/ins/estimated_pose.h"

namespace cvslam {

/// Directions of a stereo observation's joint state: rows 0–8 the vehicle pose (position, body
/// velocity, attitude), rows 9–11 the landmark; one column per direction.
constexpr int kObservedPoseEntries = 9;
constexpr int kObservedEntries = kObservedPoseEntries + 3;
/// The two tilt directions (tiltDirections), in those rows.
using TiltDirections = Eigen::Matrix<double, kObservedEntries, 2>;

/// The yaw direction e3 × p of a point p [m]: how p moves per radian of global yaw.
Eigen::Vector3d yawDirectionOfPoint(const Eigen::Vector3d& p);

/// Changes one stereo observation's Jacobians [H_v | H_L] (4 × (9 + 3)) as little as possible
/// so that they annihilate the global translation and the yaw direction [u_v(0:9) ; u_L]
/// (N, 12 × 4): H ← H − H N (Nᵀ W⁻¹ N)⁻¹ Nᵀ W⁻¹, the smallest change in the norm
/// Σ_j w_j |ΔH_j|² over the columns. Position and landmark columns are in pixels per metre,
/// attitude columns in pixels per radian; `attitude_lever_m` = ℓ puts them on one scale — an
/// attitude change of ΔH moves the image like a position change of ΔH / ℓ at range ℓ — so
/// w = 1/ℓ² on the attitude columns and 1 elsewhere. ℓ = 1 m: the unweighted projection
/// H − H N (NᵀN)⁻¹ Nᵀ. The bias entries of u_v are zero by construction (the transition
/// does not couple yaw into the biases).
/// With `tilt` (columns: rotations about N's x and y axes, rows as N's), H N = 0 for them too.
void constrainStereoJacobian(const Eigen::VectorXd& u_v, const Eigen::Vector3d& u_L,
                             double attitude_lever_m, StereoCamera::Matrix4x9d* H_v,
                             StereoCamera::Matrix4x3d* H_L, const TiltDirections* tilt = nullptr);

/// The tilt directions of one observation: how the vehicle pose `x` (9 entries: position,
/// body velocity, attitude in x's coordinates) and a landmark at `p_ref` move per radian of a
/// rigid rotation of the world about N's x axis (column 0) and y axis (column 1). A stereo
/// observation alone cannot tell such a rotation, whatever gravity tells the IMU: its
/// Jacobian at one point (x, p_ref) annihilates them. Linearised at a landmark estimate that
/// changes between updates, it does not, and the vision updates inform the tilt.
TiltDirections tiltDirections(const EstimatedPose& x, const Eigen::Vector3d& p_ref);

}  // namespace cvslam
