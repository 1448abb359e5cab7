#pragma once
// Live sensor streams of a simulated team (sim::Simulator): per agent the simulator's IMU,
// the ground truth at every IMU sample, and at every camera epoch either a rendered stereo
// pair (StereoRenderer at the true pose, the agent's camera) or the simulator's feature
// observations. Play time = dataset time (simulations start at 0).
#include <memory>
#include <vector>
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/render/world.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/sensors/sensor_stream.h"
#include "cvslam/sim/simulator.h"

namespace cvslam {

struct SimulatedSensorOptions {
  bool render = true;                    ///< true: rendered images; false: feature observations
  render::WorldOptions render_world;     ///< the textured world (chooseRenderWorld)
  render::RenderOptions render_options;  ///< the renderer's (RenderWorldChoice::render)
  bool ground_truth = true;              ///< emit ground truth at every IMU sample
  double start = 0.0;                    ///< skip (without rendering) everything before this [s]
};

/// A simulated team: the simulator (ground-truth landmarks), the rendered world (if any) and
/// one stream per agent, all sharing them.
struct SimulatedTeam {
  std::shared_ptr<sim::Simulator> simulator;
  std::shared_ptr<const render::World> render_world;  ///< null when not rendering
  std::vector<std::unique_ptr<AgentSensorStream>> streams;
};

Expected<SimulatedTeam> simulateTeam(const sim::Scenario& scenario,
                                     const SimulatedSensorOptions& options);

/// Ground truth of the simulator in the stream's terms.
VehiclePose vehiclePose(const sim::GroundTruth& truth);

}  // namespace cvslam
