#pragma once
// An agent's calibration and filter start taken from a simulated scenario: the agent's
// camera, its IMU's noise densities, the scenario's initial estimate (the truth, or a sample
// around it, thesis §6.3.1) and the scenario world's true landmarks. SimulatedTeamRun
// (cvslam_run) and a scenario-driven cvslam_agent or ground station all start their filters
// through here, so that the in-process and the process paths begin identically. Nothing here
// simulates a sensor or renders: the processes that only estimate link neither.

#include "cvslam/core/status.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario/scenario_agent.h"
#include "cvslam/slam/agent_calibration.h"
#include "cvslam/slam/agent_setup.h"

namespace cvslam {

/// A simulated agent: the IMU's datasheet noise replaces the configured densities when the
/// simulated IMU is noisy; the state starts at the scenario's initial estimate, and the gyro
/// bias at the one measured at rest before the flight when a recorded IMU has such a period
/// (agent_setup.h, setGyroBiasFromRest).
AgentFilterSetup simulatedAgentSetup(const sim::ScenarioAgent& agent,
                                     const VisualInertialSlamOptions& options);

/// The agent `agent_id` of the scenario (error if it has none by that id).
Expected<AgentCalibration> calibrationFromScenario(const sim::Scenario& scenario, int agent_id,
                                                   const VisualInertialSlamOptions& options);

}  // namespace cvslam
