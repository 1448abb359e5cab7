// cvslam_agent — one UAV's cooperative VSLAM as a process (docs/architecture.md,
// docs/run_format.md): subscribes its sensor streams over LCM, runs the agent pipeline (front end +
// filter), publishes its pose, heartbeat and lockstep status, cooperates with its peers in DC mode
// or through the ground station in CC mode, writes its run record. A thin shell: calibration and
// filter in common/ (AgentPipeline, AgentConfig), LCM in transport/ (AgentNode, DcLink, CcLink).
//
//   cvslam_agent --id 1 --scenario config/scenarios/team3_aerial.yaml --out runs/team3

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <random>
#include <string>

#include "cvslam/coop/agent_config.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/options_description.h"
#include "cvslam/io/process_shell.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/agent_node.h"
#include "cvslam/lcm/cc_link.h"
#include "cvslam/lcm/dc_link.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario_setup/scenario_calibration.h"
#include "cvslam/slam/agent_calibration.h"
#include "cvslam/slam/visual_slam_pipeline.h"
#include "cvslam/vision/vocabulary.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage =
    R"(usage: cvslam_agent --id N (--scenario FILE | --calibration DIR) [options]

One UAV of the team as a process: subscribes UAV<N>/IMU, UAV<N>/FEATURES or UAV<N>/STEREO
and UAV<N>/GT (cvslam_replay), runs its VSLAM, publishes UAV<N>/POSE per frame,
TEAM/SUMMARY (heartbeat with receive counters) and UAV<N>/STATUS (lockstep), cooperates
with every peer it hears in DC mode; in CC mode sends UAV<N>/OBS to cvslam_ground_station and
publishes its estimate of the frame when it comes in time (else its own); writes DIR/agent_<N>/ (docs/run_format.md)
periodically and on exit (SIGINT/SIGTERM), with the configuration as run (file +
overrides) in DIR/agent_<N>/config_used.yaml: give it back with --config.

options:
  --id N                  this UAV's id (≥ 1)                                   [required]
  --scenario FILE         calibration, IMU noise and initial estimate of agent N of a
                          simulated scenario (as cvslam_run builds them)
  --calibration DIR       EuRoC folder (DIR/mav0 or DIR): cam0/cam1/imu0 sensor.yaml; the
                          filter starts at the first UAV<N>/GT pose (or --start rest|dynamic|auto)
  --start MODE            overrides agent.start: known — the scenario's initial estimate,
                          else the first ground truth; without ground truth, in the agent's
                          own gravity-aligned frame (evaluate with cvslam_eval --align yaw):
                          rest — from the IMU's first rest period; dynamic — in motion, from
                          the first frames and the IMU; auto — rest if at rest, else dynamic
  --starts known|unknown  scenario: overrides every UAV's `start:` (as cvslam_run --starts;
                          unknown: the scenario's initial estimate in the agent's own frame)
                          In DC, an agent whose start is not known (--starts unknown, or
                          --start rest|dynamic|auto) estimates the frames to its peers from
                          place exchanges before it fuses anything (docs/merge.md).
  --config FILE           agent configuration (default: config/agent.yaml of the source tree)
  --profile NAME          the filter profile beneath the configuration, in place of the one
                          it names: invariant_ekf (shipped) | thesis_ekf (chapter 5);
                          config/profiles/
  --set SECTION.KEY=VALUE one key of the configuration changed, e.g. map.kind=full or
                          frontend.detector.type=orb (repeatable; the rest stays as --config)
  --mode single|dc|cc     single: alone; dc: decentralised cooperation; cc: centralised, with
                          cvslam_ground_station (default single)
  --gs-wait S             cc: overrides agent.cc.gs_wait_s, how long a frame waits for the
                          ground station's estimate [s]
  --filter ekf|nhinf      overrides filter.type of the configuration
  --map knearest|full     overrides map.kind of the configuration
  --attitude error_state|euler
                          overrides ins.attitude (euler: the thesis's model)
  --passes N              overrides slam.observation_passes (thesis §5.7.3)
  --detector NAME         images: overrides frontend.detector.type (adaptive_sift | sift | orb)
  --ci METHOD             dc: overrides coop.ci_method (adaptive | fast | optimal_trace |
                          optimal_determinant | optimal_vehicle)
  --both-ways             dc: overrides coop.both_ways to true (the default)
  --one-way               dc: overrides coop.both_ways to false (thesis §6.6.5)
  --lcm-url URL           LCM provider (default udpm://239.255.76.67:7667?ttl=0)
  --coop-lcm-url URL      cooperation on this provider (e.g. a LAN, ttl=1) while the sensor
                          streams stay on --lcm-url (the vehicle's own; DC mode)
  --auth-key FILE         team key: sign cooperation messages and accept only those signed
                          with it (HMAC-SHA256, replay window; docs/transport.md)
  --out DIR               run record folder (none if not given)
  --seed N                scenario: overrides its seed (as given to cvslam_replay)
  --duration S            scenario: simulate only the first S seconds (as cvslam_replay)
  --idle-exit S           exit after S seconds without sensor data (default: never)
  --verbose               more messages on stderr, the effective configuration first
  -h, --help              this text
)";

const cvslam::cli::ProcessShell shell("cvslam_agent");
int fail(const std::string& message) {
  return shell.fail(message);
}

struct Args {
  int id = 0;
  cvslam::AgentConfigArgs config;  // --config and the overrides shared with cvslam_run
  std::string scenario, calibration, mode = "single", url, out, start, auth_key, coop_url;
  std::string starts;  ///< --starts: "" (as the scenario says) | known | unknown
  long long seed = -1;
  std::string gs_wait;  // --gs-wait, as given
  double duration = -1.0, idle_exit = 0.0;
  bool verbose = false;
};

/// Parses the command line; nullopt: go on, else the exit status.
std::optional<int> parseArgs(int argc, char** argv, Args* a) {
  CLI::App app("one UAV of the team as a process", "cvslam_agent");
  // As the hand-written loop did: an option given twice takes its last value (scripts pass
  // defaults first, the caller's extra arguments after them).
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--id", a->id)
      ->required()
      ->check(cvslam::cli::numberValidator("ID", "an integer ≥ 1", [](double x) {
        return x >= 1 && x == std::floor(x) && x <= 1e6;
      }));
  CLI::Option* scenario = app.add_option("--scenario", a->scenario);
  CLI::Option* calibration = app.add_option("--calibration", a->calibration);
  scenario->excludes(calibration);
  app.add_option("--mode", a->mode)->check(CLI::IsMember({"single", "dc", "cc"}));
  app.add_option("--gs-wait", a->gs_wait)->check(cvslam::cli::kNonNegative);
  app.add_option("--lcm-url", a->url);
  app.add_option("--auth-key", a->auth_key);
  app.add_option("--coop-lcm-url", a->coop_url);
  app.add_option("--out", a->out);
  app.add_option("--seed", a->seed)->check(cvslam::cli::kCount);
  app.add_option("--duration", a->duration)->check(cvslam::cli::kPositive);
  app.add_option("--idle-exit", a->idle_exit)->check(cvslam::cli::kPositive);
  app.add_option("--start", a->start)->check(CLI::IsMember({"known", "rest", "dynamic", "auto"}));
  app.add_option("--starts", a->starts)->check(CLI::IsMember({"known", "unknown"}));
  app.add_flag("--verbose", a->verbose);
  a->config.addTo(app);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return exit_code;
  if (a->scenario.empty() == a->calibration.empty())
    return fail("give exactly one of --scenario and --calibration (try --help)");
  if (!a->calibration.empty() && (a->seed >= 0 || a->duration > 0 || !a->starts.empty()))
    return fail("--seed, --duration and --starts need --scenario");
  if (a->mode != "dc" && a->config.anyCoop())
    return fail("--ci, --both-ways and --one-way need --mode dc");
  if (a->mode != "cc" && !a->gs_wait.empty()) return fail("--gs-wait needs --mode cc");
  return std::nullopt;
}

/// The filter's calibration: agent N of a scenario (as cvslam_run builds it) or an EuRoC
/// folder; `info` gets the scenario facts for run.json, `start_known` whether the scenario
/// gives the agent its start in the team's frame (an EuRoC folder's ground truth does).
cvslam::Expected<cvslam::AgentCalibration> loadCalibration(
    const Args& args, const cvslam::VisualInertialSlamOptions& options, cvslam::RunInfo* info,
    bool* start_known) {
  *start_known = true;
  if (args.scenario.empty()) {
    info->scenario = args.calibration;
    return cvslam::calibrationFromEuroc(args.calibration, options);
  }
  auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
  if (!scenario.ok()) return scenario.status();
  if (args.seed >= 0) scenario->seed = static_cast<uint64_t>(args.seed);
  if (args.duration > 0) scenario->duration = std::min(scenario->duration, args.duration);
  if (!args.starts.empty())
    if (Status s = scenario->overrideStarts(args.starts == "known"); !s.ok())
      return Status::Error("--starts: " + s.message());
  for (const cvslam::sim::AgentSpec& a : scenario->agents)
    if (a.id == args.id) *start_known = a.start_known;
  info->scenario = args.scenario;
  info->seed = scenario->seed;
  info->duration_s = scenario->duration;
  return cvslam::calibrationFromScenario(*scenario, args.id, options);
}

/// DIR/agent_<N>/config_used.yaml, and DIR/run.json unless a peer wrote it first.
Status writeRunConfig(const Args& args, const cvslam::AgentConfig& config, cvslam::RunInfo info) {
  if (args.out.empty()) return Status::Ok();
  const std::string dir = cvslam::agentDir(args.out, args.id);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::Error("cannot create " + dir + ": " + ec.message());
  if (Status s = config.effective.write(dir + "/config_used.yaml"); !s.ok()) return s;
  if (std::filesystem::exists(args.out + "/run.json")) return Status::Ok();
  info.program = "cvslam_agent";
  info.mode = args.mode;
  info.filter = config.filterName();
  info.map = config.mapName();
  info.config = config.effective.path();
  return cvslam::writeRunInfo(args.out, info);
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (auto exit_code = parseArgs(argc, argv, &args)) return *exit_code;
  cvslam::transport::AgentNodeOptions node;
  Status node_status;
  auto config = cvslam::AgentConfig::load(
      args.config, CVSLAM_CONFIG_DIR "/agent.yaml",
      [&](const cvslam::ConfigNode& root) { node_status = node.load(root.child("agent")); });
  if (!config.ok()) return fail(config.status().message());
  if (!node_status.ok()) return fail(node_status.message());
  if (!args.start.empty())
    if (Status s = config->effective.override(node, {"agent"}, "start", args.start, "--start");
        !s.ok())
      return fail(s.message());
  if (!args.gs_wait.empty())
    if (Status s = config->effective.override(node.cc, {"agent", "cc"}, "gs_wait_s", args.gs_wait,
                                              "--gs-wait");
        !s.ok())
      return fail(s.message());

  cvslam::RunInfo info;
  bool start_known = true;
  auto calibration = loadCalibration(args, config->slam, &info, &start_known);
  if (!calibration.ok()) return fail(calibration.status().message());
  // An agent not started in the team's frame does not fuse a peer's landmarks before it found
  // the frame between them, and its summaries say so to its peers (docs/merge.md).
  config->coop.frames_given =
      start_known && node.start == cvslam::transport::AgentNodeOptions::Start::kKnown;
  if (args.mode == "cc" && !config->coop.frames_given)
    return fail(
        "--mode cc needs the start known (the ground station holds every UAV in the team's "
        "frame); an agent that starts unknown or with --start rest|dynamic|auto runs --mode dc "
        "or single");

  // The image path (used when UAV<N>/STEREO arrives), with the feature-index vocabulary.
  auto vocabulary = cvslam::loadFeatureIndexVocabulary(config->frontend, config->effective.dir());
  if (!vocabulary.ok()) return fail(vocabulary.status().message());
  auto images =
      cvslam::VisualSlamPipeline::create(config->frontend, calibration->camera, *vocabulary);
  if (!images.ok()) return fail(images.status().message());

  node.id = args.id;
  node.mode = args.mode;
  node.out_dir = args.out;
  node.idle_exit_s = args.idle_exit;
  node.verbose = args.verbose;
  node.filter_name = config->filterName();
  if (!args.url.empty()) node.url = args.url;
  node.coop_url = args.coop_url;
  auto key = cvslam::transport::TeamKey::forOption(args.auth_key);
  if (!key.ok()) return fail(key.status().message());
  node.auth_key = *key;
  std::random_device entropy;
  node.boot_id = (static_cast<int64_t>(entropy()) << 31) ^ static_cast<int64_t>(entropy()) ^
                 static_cast<int64_t>(getpid());

  std::unique_ptr<cvslam::transport::CooperationLink> coop;
  if (args.mode == "dc") {
    coop =
        std::make_unique<cvslam::transport::DcLink>(args.id, config->coop, node.boot_id, args.out);
  } else if (args.mode == "cc") {
    coop = std::make_unique<cvslam::transport::CcLink>(args.id, node.cc, args.out);
  }
  if (Status s = writeRunConfig(args, *config, info); !s.ok()) return fail(s.message());

  shell.stopOnSignals();
  auto agent = cvslam::transport::AgentNode::create(node, std::move(*calibration),
                                                    std::move(*images), std::move(coop));
  if (!agent.ok()) return fail(agent.status().message());
  if (args.verbose) {
    std::vector<cvslam::ConfigNode::Value> values = config->values();
    const auto agent_section = cvslam::inSection(cvslam::optionValues(node), "agent");
    values.insert(values.end(), agent_section.begin(), agent_section.end());
    std::fprintf(stderr, "cvslam_agent %d: effective configuration\n%s", args.id,
                 cvslam::formatOptionValues(values).c_str());
    std::fprintf(stderr, "cvslam_agent %d: %s mode, boot id %lld, listening\n", args.id,
                 args.mode.c_str(), static_cast<long long>(node.boot_id));
  }
  Status s = (*agent)->run(shell.stopFlag());
  std::printf("cvslam_agent: %s\n", (*agent)->report().c_str());
  if (!s.ok()) return fail(s.message());
  return 0;
}
