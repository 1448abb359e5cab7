#include "cvslam/scenario_setup/scenario_calibration.h"

#include <memory>
#include <string>
#include <vector>

#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

AgentFilterSetup simulatedAgentSetup(const sim::ScenarioAgent& agent,
                                     const VisualInertialSlamOptions& options) {
  VisualInertialSlamOptions agent_options = options;
  const sim::ImuOptions& imu = agent.spec().imu;
  if (imu.noise) {
    agent_options.ins.gyro_noise_density = imu.gyro_noise_density;
    agent_options.ins.accel_noise_density = imu.accel_noise_density;
    agent_options.ins.gyro_random_walk = imu.gyro_random_walk;
    agent_options.ins.accel_random_walk = imu.accel_random_walk;
    // A synthesised IMU's own densities are its truth; a recording's (imu.recording) are its
    // datasheet, which a real IMU in flight exceeds.
    // Nor is there anything to measure in flight that the filter does not know already.
    if (imu.recording.empty()) {
      agent_options.ins.datasheet_random_walk_scale = 1.0;
      agent_options.ins.noise_monitor.enabled = false;
    }
  }
  // Nor did anyone draw a recording's turn-on accelerometer bias from the prior (slam_options.h).
  if (!imu.recording.empty())
    agent_options.slam.initial_accel_bias_sigma = agent_options.slam.recorded_accel_bias_sigma;
  const sim::InitialEstimate& init = agent.initialEstimate();
  AgentFilterSetup setup = initialEstimateSetup(init.state.t_us, init.state.p_BinN, init.state.v_B,
                                                init.state.euler, init.sigma, agent_options);
  // The bias estimates drawn from the stated bias σ around the synthesised IMU's true turn-on
  // biases, so that the whole initial error matches P0 (a recording's biases are unknown).
  if (init.sigma.perturb && init.sigma.perturb_biases && agent_options.ins.estimate_imu_bias &&
      imu.recording.empty()) {
    setup.x0.segment<3>(vehicle::kAccelBias) =
        init.state.accel_bias +
        agent_options.slam.initial_accel_bias_sigma * init.bias_draw.head<3>();
    setup.x0.segment<3>(vehicle::kGyroBias) =
        init.state.gyro_bias +
        agent_options.slam.initial_gyro_bias_sigma * init.bias_draw.tail<3>();
  }
  // A recorded IMU carries its real turn-on bias, which the known pose says nothing about. When
  // it recorded the vehicle at rest before the flight, the bias is measured there, as an
  // operator calibrates before take-off (the static initialiser's rest test and averaging).
  const std::vector<ImuSample> before = agent.imuBeforeStart();
  if (!before.empty()) {
    const Expected<StaticInitialization> rest =
        initializeAtRest(before, StaticInitializerOptions(), agent_options.ins.gravity,
                         agent_options.slam.initial_accel_bias_sigma);
    if (rest.ok()) setGyroBiasFromRest(*rest, &setup);
  }
  return setup;
}

Expected<AgentCalibration> calibrationFromScenario(const sim::Scenario& scenario, int agent_id,
                                                   const VisualInertialSlamOptions& options) {
  const sim::AgentSpec* spec = nullptr;
  for (const sim::AgentSpec& a : scenario.agents)
    if (a.id == agent_id) spec = &a;
  if (spec == nullptr) {
    return Status::Error("scenario " + scenario.source + " has no agent with id " +
                         std::to_string(agent_id));
  }
  auto agent = sim::ScenarioAgent::create(scenario, *spec);
  if (!agent.ok()) return agent.status();
  auto world = scenario.generateWorld();
  if (!world.ok()) return world.status();
  AgentCalibration c;
  c.source = scenario.source + " (agent " + std::to_string(agent_id) + ")";
  c.camera = agent->camera();
  c.setup = simulatedAgentSetup(*agent, options);
  c.options = c.setup->options;
  if (!spec->start_known) c.own_frame_in_world = agent->ownFrameInWorld();
  // Feature-level frames name their landmarks by true id: the scenario's world knows them,
  // and the agent's own frame (the world's unless its start is unknown) is where it maps them.
  auto shared = std::make_shared<const sim::World>(std::move(*world));
  auto own = std::make_shared<const sim::ScenarioAgent>(std::move(*agent));
  c.landmark_truth = [shared, own](int64_t id, Eigen::Vector3d* p) {
    const auto& landmarks = shared->landmarks();
    if (id < 0 || id >= static_cast<int64_t>(landmarks.size())) return false;
    *p = own->toOwnFrame(landmarks[static_cast<std::size_t>(id)].p_LinN);
    return true;
  };
  return c;
}

}  // namespace cvslam
