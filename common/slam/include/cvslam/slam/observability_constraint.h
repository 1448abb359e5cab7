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
// complement of span{translation, u}, the smallest change (Frobenius) with H N = 0.
// The translation directions are already in the null space of the stereo Jacobian (it
// depends on p_L − p), and the INS transition maps them onto themselves. The vehicle's u_v
// comes from the vehicle model (filter/vehicle_model.h: vehicle_model::yawDirection).

#include <Eigen/Core>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/slam/loop_alignment.h"

namespace cvslam {

/// The yaw direction e3 × p of a point p [m]: how p moves per radian of global yaw.
Eigen::Vector3d yawDirectionOfPoint(const Eigen::Vector3d& p);

/// Projects one stereo observation's Jacobians [H_v | H_L] (4 × (9 + 3)) so that they
/// annihilate the global translation and the yaw direction [u_v(0:9) ; u_L]:
/// H ← H − H N (Nᵀ N)⁻¹ Nᵀ with N the 12 × 4 null-space basis. The bias entries of u_v are
/// zero by construction (the transition does not couple yaw into the biases).
void constrainStereoJacobian(const Eigen::VectorXd& u_v, const Eigen::Vector3d& u_L,
                             StereoCamera::Matrix4x9d* H_v, StereoCamera::Matrix4x3d* H_L);

/// The same constraint with the change confined (observability_constraint.h, SlamOptions::
/// oc_projection): the translation residual H_p + H_L is split evenly between H_p and H_L,
/// then the yaw residual r = H_v u_v + H_L u_L is removed from the attitude columns alone,
/// H_att ← H_att − r u_attᵀ / |u_att|² (u_att: the attitude part of u_v, never zero). The
/// position and landmark Jacobians — what makes a stereo observation informative — keep their
/// linearisation; only ∂h/∂(attitude) along the yaw direction changes.
void constrainStereoJacobianAttitude(const Eigen::VectorXd& u_v, const Eigen::Vector3d& u_L,
                                     StereoCamera::Matrix4x9d* H_v, StereoCamera::Matrix4x3d* H_L);

/// Moves a yaw direction e3 × p (given as a 3-vector, its z ignored) with the rigid loop
/// alignment p ↦ fit.apply(p), as the alignment moves the estimate it was taken at.
Eigen::Vector3d moveYawDirection(const Eigen::Vector3d& u_position, const LoopAlignment& fit);

}  // namespace cvslam
