#pragma once
// A simulation scenario (config/scenarios/*.yaml): seed, duration, world and a team of agents,
// each with its trajectory, initial-state uncertainty, IMU, stereo camera and pixel noise
// (thesis §5.9, §6.4). Loaded with the options pattern: every key has a default, errors name
// the file and the key, unknown keys are errors.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/initial_uncertainty.h"
#include "cvslam/scenario/gps_options.h"
#include "cvslam/scenario/imu_options.h"
#include "cvslam/scenario/pixel_noise_options.h"
#include "cvslam/scenario/trajectory_spec.h"
#include "cvslam/scenario/world.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

struct AgentSpec {
  int id = 1;  ///< agent id (> 0, unique), also selects the agent's RNG streams
  TrajectorySpec trajectory;
  InitialUncertainty initial;
  ImuOptions imu;
  StereoCameraOptions camera;
  double camera_rate_hz = 10.0;  ///< stereo frame rate [Hz]
  /// Frames are taken this long after the IMU's ticks (a camera that the IMU does not
  /// trigger; 0: both on one grid, as EuRoC's rig) [s], 0 ≤ delay < 1 / camera_rate_hz.
  double camera_delay_s = 0.0;
  PixelNoiseOptions pixel_noise;
  /// Section `gps:` (gps_simulator.h): a GPS receiver on this UAV, with outage windows for
  /// GPS-denied stretches; the filter uses its fixes when the agent's `gps.enabled` is true.
  bool has_gps = false;
  GpsOptions gps;
  /// `start: known` (default): the agent starts in the team's frame, the scenario's world
  /// (thesis §6.3.1). `start: unknown`: nobody tells it where it is; it estimates in its own
  /// gravity-aligned frame, with the origin and heading of its true start pose (as an agent
  /// started at rest does), and must find its peers' frames itself (docs/merge.md).
  bool start_known = true;

  Status load(const ConfigNode& node, const std::string& base_dir);
};

/// Extends `area` by where `trajectory` flies over [time_offset, time_offset + duration],
/// sampled every 0.5 s (horizontal NED position).
void extendByFlight(const Trajectory& trajectory, double time_offset, double duration,
                    Eigen::AlignedBox2d* area);

struct Scenario {
  std::string name;        ///< free text
  std::string source;      ///< file it came from
  uint64_t seed = 1;       ///< master seed: world and every agent stream derive from it
  double duration = 60.0;  ///< simulated time [s]
  WorldOptions world;
  /// Section `render:` as YAML text ("" if the scenario has none): the textured world and the
  /// renderer's options for image sensing, `render: {world: {kind: aerial, ...}, options:
  /// {...}}`, parsed by simrun/scenario_rendering.h. Kept as text so that the programs that
  /// only estimate (cvslam_agent, the ground station) read a scenario without the renderer.
  std::string render_yaml;
  std::vector<AgentSpec> agents;
  /// The horizontal area the feature-level world is laid out around (World, plus world.margin).
  /// load() sets it to the area the whole team flies over the whole duration, so that a run of
  /// some agents or of the first seconds (cvslam_run --agents, --duration) happens in the same
  /// world as the full run, not in another landmark layout. Empty: the simulator takes the
  /// area `agents` fly over `duration`.
  Eigen::AlignedBox2d world_region;

  /// The feature-level world of the scenario (World::generate over world_region, or the area
  /// the agents fly, plus world.margin), the same for the simulator and for an agent that only
  /// needs its true landmarks.
  Expected<World> generateWorld() const;

  /// Every agent's `start:` set to known or unknown (cvslam_run and cvslam_agent --starts);
  /// refused, as the file refuses it, for an unknown start with a gps section.
  Status overrideStarts(bool known);

  /// Loads and validates a scenario file (also checks that open trajectories last long enough).
  static Expected<Scenario> loadFile(const std::string& path);
  /// Same from YAML text; `base_dir` resolves relative file names.
  static Expected<Scenario> fromString(const std::string& yaml, const std::string& source,
                                       const std::string& base_dir = ".");
  Status load(const ConfigNode& node, const std::string& base_dir);
};

}  // namespace cvslam::sim
