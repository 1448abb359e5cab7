#pragma once
// One agent's configuration as every tool loads it (cvslam_run, cvslam_agent): the sections of
// config/agent.yaml — filter/ins/map/slam (VisualInertialSlamOptions), frontend
// (VisualFrontEndOptions), coop (DcCooperationOptions) and whatever the tool reads itself
// (cvslam_agent's `agent:`) — plus the command-line overrides the tools share (--set, --filter,
// --map, --attitude, --passes, --detector, --ci, --both-ways, --one-way), kept as the
// effective YAML (io/effective_config.h) that the run records in agent_<id>/config_used.yaml
// (docs/run_format.md). It lives in coop, the lowest module that knows every section.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/core/status.h"
#include "cvslam/io/effective_config.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "cvslam/slam/visual_slam_pipeline.h"

namespace cvslam {

/// The shared command-line options (each empty / 0 / false: not given).
struct AgentConfigArgs {
  std::string config;  ///< --config FILE ("" : default_config when it exists, else defaults)
  /// --profile NAME: the filter profile (config/profiles/NAME.yaml) beneath the file, in place of
  /// the one it names.
  std::string profile;
  std::string filter, map, detector, ci, attitude;
  int passes = 0;
  bool both_ways = false, one_way = false;
  /// --set SECTION.KEY=VALUE (repeatable): any key of the file, applied before the options are
  /// read, so unknown keys and bad values are reported as the file's would be.
  std::vector<std::string> set;

  /// Adds --config, --profile, --set, --filter, --map, --attitude, --passes, --detector, --ci,
  /// --both-ways and --one-way to `app` (help texts: the tool's usage text).
  void addTo(CLI::App& app);
  /// The options that need cooperation (--ci, --both-ways, --one-way) were given.
  bool anyCoop() const { return !ci.empty() || both_ways || one_way; }
};

struct AgentConfig {
  VisualInertialSlamOptions slam;
  VisualFrontEndOptions frontend;
  coop::DcCooperationOptions coop;
  EffectiveConfig effective;  ///< the file + overrides, for config_used.yaml

  /// Loads `args.config` (or `default_config` when no --config was given and it exists, else
  /// built-in defaults) with the profile it names (looked up in `profiles/` beside it, then
  /// beside `default_config`), lets `tool_sections` read the sections only the tool knows
  /// (others are reported as unknown keys), applies the overrides and checks the filter's
  /// options.
  /// Relative vocabulary names are resolved against the file's folder, so that
  /// config_used.yaml works from the run folder.
  static Expected<AgentConfig> load(const AgentConfigArgs& args, const std::string& default_config,
                                    const std::function<void(const ConfigNode&)>& tool_sections);

  /// Every option the filter, the front end and the cooperation run with (defaults included),
  /// as one YAML document in the file's layout (options_description.h).
  std::vector<ConfigNode::Value> values() const;
  std::string filterName() const;  ///< ekf | nhinf
  std::string mapName() const;     ///< knearest | full
};

}  // namespace cvslam
