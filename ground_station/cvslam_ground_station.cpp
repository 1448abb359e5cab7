// cvslam_ground_station — the centralised ground station of CC-VSLAM as a process
// (docs/ground_station.md; thesis §6.3): subscribes every UAV's observation batches and own
// estimates over LCM, runs the joint filter, publishes each UAV's estimate, the joint map and
// its heartbeat, writes DIR/ground_station/. A thin shell: the filter in common/coop
// (CcTeamFilter), LCM in transport/ (GroundStationNode).
//
//   cvslam_ground_station --agents 1,2,3 --scenario config/scenarios/team3_aerial.yaml --out
//   runs/t3

#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/options_description.h"
#include "cvslam/io/process_shell.h"
#include "cvslam/lcm/ground_station_node.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario_setup/scenario_calibration.h"
#include "cvslam/slam/agent_calibration.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage =
    R"(usage: cvslam_ground_station --agents LIST (--scenario FILE | --calibration ID:DIR ...) [options]

The centralised ground station (CC-VSLAM): subscribes UAV<id>/OBS (observation batches),
UAV<id>/POSE (each agent's own estimate: starts its vehicle, and restarts it after a restart),
UAV<id>/STATUS and UAV<id>/GT of the UAVs in LIST; runs the joint filter; publishes
UAV<id>/GS_STATE after each batch of that UAV, GS/MAP periodically and its heartbeat on
UAV0/STATUS (give 0 to cvslam_replay --participants for lockstep); writes DIR/ground_station/
(docs/run_format.md) periodically and on exit (SIGINT/SIGTERM).

options:
  --agents LIST           UAV ids served, e.g. 1,2,3                            [required]
  --scenario FILE         each UAV's camera and IMU noise as the agents take them from a
                          simulated scenario (give the agents' --seed/--duration too)
  --calibration ID:DIR    UAV ID's EuRoC folder (cam0/cam1/imu0 sensor.yaml); repeatable
  --config FILE           configuration (default: config/ground_station.yaml of the source tree)
  --filter ekf|nhinf      overrides filter.type of the configuration
  --association KIND      overrides cc.association: true_ids (feature-level simulation: the
                          agents name landmarks by their true ids) | local_ids (images: each
                          agent's own ids, matched across agents by feature index + descriptor)
  --lcm-url URL           LCM provider (default udpm://239.255.76.67:7667?ttl=0)
  --auth-key FILE         team key: sign cooperation messages and accept only those signed
                          with it (HMAC-SHA256, replay window; docs/transport.md)
  --out DIR               run folder: writes DIR/ground_station/ (none if not given)
  --seed N                scenario: overrides its seed
  --duration S            scenario: only the first S seconds
  --idle-exit S           exit after S seconds without agent messages (default: never)
  --verbose               more messages on stderr, the effective configuration first
  -h, --help              this text
)";

const cvslam::cli::ProcessShell shell("cvslam_ground_station");
int fail(const std::string& message) {
  return shell.fail(message);
}

struct Args {
  std::vector<int> agents;
  std::vector<std::string> calibrations;  // ID:DIR
  std::string scenario, config, filter, association, url, out, auth_key;
  long long seed = -1;
  double duration = -1.0, idle_exit = 0.0;
  bool verbose = false;
};

std::optional<int> parseArgs(int argc, char** argv, Args* a) {
  CLI::App app("the centralised ground station", "cvslam_ground_station");
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--agents", a->agents)
      ->required()
      ->delimiter(',')
      ->check(cvslam::cli::numberValidator("ID", "an integer ≥ 1", [](double x) {
        return x >= 1 && x == std::floor(x) && x <= 1e6;
      }));
  CLI::Option* scenario = app.add_option("--scenario", a->scenario);
  CLI::Option* calibration = app.add_option("--calibration", a->calibrations)
                                 ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  scenario->excludes(calibration);
  app.add_option("--config", a->config);
  app.add_option("--filter", a->filter)->check(CLI::IsMember({"ekf", "nhinf"}));
  app.add_option("--association", a->association)->check(CLI::IsMember({"true_ids", "local_ids"}));
  app.add_option("--lcm-url", a->url);
  app.add_option("--auth-key", a->auth_key);
  app.add_option("--out", a->out);
  app.add_option("--seed", a->seed)->check(cvslam::cli::kCount);
  app.add_option("--duration", a->duration)->check(cvslam::cli::kPositive);
  app.add_option("--idle-exit", a->idle_exit)->check(cvslam::cli::kPositive);
  app.add_flag("--verbose", a->verbose);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return exit_code;
  if (a->scenario.empty() == a->calibrations.empty())
    return fail("give --scenario or --calibration ID:DIR (try --help)");
  if (a->scenario.empty() && (a->seed >= 0 || a->duration > 0))
    return fail("--seed and --duration need --scenario");
  return std::nullopt;
}

/// Each UAV's camera and IMU noise: from the scenario (as the agents build them) or from its
/// EuRoC folder; `info` gets the scenario facts for run.json.
cvslam::Expected<std::map<int, cvslam::transport::GroundStationAgent>> loadAgents(
    const Args& args, const cvslam::VisualInertialSlamOptions& options, cvslam::RunInfo* info) {
  std::map<int, cvslam::transport::GroundStationAgent> agents;
  auto keep = [&](int id, const cvslam::AgentCalibration& c) {
    agents[id] = {c.camera, c.options.ins, c.landmark_truth};
  };
  if (!args.scenario.empty()) {
    auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
    if (!scenario.ok()) return scenario.status();
    if (args.seed >= 0) scenario->seed = static_cast<uint64_t>(args.seed);
    if (args.duration > 0) scenario->duration = std::min(scenario->duration, args.duration);
    info->scenario = args.scenario;
    info->seed = scenario->seed;
    info->duration_s = scenario->duration;
    for (int id : args.agents) {
      auto c = cvslam::calibrationFromScenario(*scenario, id, options);
      if (!c.ok()) return c.status();
      keep(id, *c);
    }
    return agents;
  }
  for (const std::string& text : args.calibrations) {
    const auto colon = text.find(':');
    int id = 0;
    if (colon == std::string::npos || std::sscanf(text.substr(0, colon).c_str(), "%d", &id) != 1 ||
        id < 1)
      return cvslam::Status::Error("--calibration wants ID:DIR, not '" + text + "'");
    auto c = cvslam::calibrationFromEuroc(text.substr(colon + 1), options);
    if (!c.ok()) return c.status();
    keep(id, *c);
    info->scenario = text.substr(colon + 1);
  }
  return agents;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (auto exit_code = parseArgs(argc, argv, &args)) return *exit_code;
  const std::string config_path =
      args.config.empty() ? std::string(CVSLAM_CONFIG_DIR "/ground_station.yaml") : args.config;
  auto root = cvslam::ConfigNode::loadFile(config_path);
  if (!root.ok()) return fail(root.status().message());
  cvslam::coop::CcTeamFilterOptions filter;
  cvslam::transport::GroundStationNodeOptions node;
  (void)filter.load(*root);
  (void)node.load(root->child("ground_station"));
  if (Status s = root->finish(); !s.ok()) return fail(s.message());
  if (!args.filter.empty())
    filter.slam.filter.type =
        args.filter == "nhinf" ? cvslam::FilterType::kNhinf : cvslam::FilterType::kEkf;

  if (!args.association.empty())
    filter.association = args.association == "local_ids" ? cvslam::coop::CcAssociation::kLocalIds
                                                         : cvslam::coop::CcAssociation::kTrueIds;

  cvslam::RunInfo info;
  info.program = "cvslam_ground_station";
  info.mode = "cc";
  info.filter = args.filter.empty()
                    ? (filter.slam.filter.type == cvslam::FilterType::kNhinf ? "nhinf" : "ekf")
                    : args.filter;
  info.config = config_path;
  info.agents = args.agents;
  auto agents = loadAgents(args, filter.slam, &info);
  if (!agents.ok()) return fail(agents.status().message());

  node.agents = args.agents;
  node.out_dir = args.out;
  node.idle_exit_s = args.idle_exit;
  node.verbose = args.verbose;
  node.filter_name = info.filter;
  if (!args.url.empty()) node.url = args.url;
  auto key = cvslam::transport::TeamKey::forOption(args.auth_key);
  if (!key.ok()) return fail(key.status().message());
  node.auth_key = *key;
  shell.stopOnSignals();
  auto gs = cvslam::transport::GroundStationNode::create(node, filter, std::move(*agents), info);
  if (!gs.ok()) return fail(gs.status().message());
  if (args.verbose) {
    std::vector<cvslam::ConfigNode::Value> values = cvslam::optionValues(filter);
    const auto node_section = cvslam::inSection(cvslam::optionValues(node), "ground_station");
    values.insert(values.end(), node_section.begin(), node_section.end());
    std::fprintf(stderr, "cvslam_ground_station: effective configuration\n%s",
                 cvslam::formatOptionValues(values).c_str());
    std::fprintf(stderr, "cvslam_ground_station: listening\n");
  }
  Status s = (*gs)->run(shell.stopFlag());
  std::printf("cvslam_ground_station: %s\n", (*gs)->report().c_str());
  if (!s.ok()) return fail(s.message());
  return 0;
}
