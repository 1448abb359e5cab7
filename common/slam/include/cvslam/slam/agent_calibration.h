#pragma once
// Where an agent process gets its calibration (cvslam_agent):
//  - a simulated scenario file (scenario_setup/scenario_calibration.h, no simulator needed):
//    the agent's camera and IMU noise and the initial estimate, built exactly as
//    SimulatedTeamRun builds them, plus the world's true landmarks (feature-level truth for
//    landmarks.csv);
//  - an EuRoC ASL folder (mav0/): cam0/cam1 sensor.yaml (rectified model, and the rectifier
//    when the cameras are distorted or not parallel) and imu0/sensor.yaml (noise densities);
//    the initial pose then comes from the first ground-truth message (thesis §6.3.1).

#include <memory>
#include <optional>
#include <string>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/slam/agent_run_recorder.h"
#include "cvslam/slam/agent_setup.h"
#include "cvslam/vision/stereo_rectifier.h"

namespace cvslam {

struct AgentCalibration {
  std::string source;                 ///< what it was read from (for messages)
  StereoCamera camera;                ///< rectified pinhole model the filter uses
  VisualInertialSlamOptions options;  ///< the configuration with the IMU's noise
  /// Filter start when known in advance (scenario); empty: from the first ground truth.
  std::optional<AgentFilterSetup> setup;
  /// Raw images must be rectified first (real EuRoC cameras).
  std::optional<vision::StereoRectifier> rectifier;
  /// True landmark positions by id when the world is known (simulated scenario); empty
  /// otherwise. Used only to score the map (landmarks.csv).
  AgentRunRecorder::LandmarkTruth landmark_truth;
  /// Simulation with the agent's start unknown: its own frame in the scenario's world,
  /// [t_N t_E t_D ψ] with p_world = R_z(ψ) p_own + t. The simulator's truth (UAV<N>/GT) is in
  /// the world; the agent records it in its own frame, as cvslam_run does. Empty: the world
  /// is the own frame.
  std::optional<Eigen::Vector4d> own_frame_in_world;
};

/// An EuRoC `mav0` folder (or its parent).
Expected<AgentCalibration> calibrationFromEuroc(const std::string& mav0_dir,
                                                const VisualInertialSlamOptions& options);

}  // namespace cvslam
