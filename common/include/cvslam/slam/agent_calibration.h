#pragma once
// Where an agent process gets its calibration (DESIGN.md §6, cvslam_agent):
//  - a simulated scenario file: the agent's camera and IMU noise and the initial estimate,
//    built exactly as SimulatedTeamRun builds them (agent_setup.h), plus the world's true
//    landmarks (feature-level truth for landmarks.csv);
//  - an EuRoC ASL folder (mav0/): cam0/cam1 sensor.yaml (rectified model, and the rectifier
//    when the cameras are distorted or not parallel) and imu0/sensor.yaml (noise densities);
//    the initial pose then comes from the first ground-truth message (thesis §6.3.1).

#include <memory>
#include <optional>
#include <string>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/sim/scenario.h"
#include "cvslam/sim/simulator.h"
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
  /// The simulated world (scenario only): true landmark positions by id.
  std::shared_ptr<const sim::Simulator> simulator;
};

/// The agent `agent_id` of the scenario (error if it has none by that id).
Expected<AgentCalibration> calibrationFromScenario(const sim::Scenario& scenario, int agent_id,
                                                   const VisualInertialSlamOptions& options);

/// An EuRoC `mav0` folder (or its parent).
Expected<AgentCalibration> calibrationFromEuroc(const std::string& mav0_dir,
                                                const VisualInertialSlamOptions& options);

}  // namespace cvslam
