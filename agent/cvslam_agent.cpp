// cvslam_agent — one UAV's cooperative VSLAM as a process (docs/architecture.md, docs/run_format.md): subscribes its
// sensor streams over LCM, runs the agent pipeline (front end + filter), publishes its pose,
// heartbeat and lockstep status, cooperates with its peers in DC mode, writes its run record.
// A thin shell: calibration and filter in common/ (AgentPipeline), LCM in transport/
// (AgentNode).
//
//   cvslam_agent --id 1 --scenario config/scenarios/team3_aerial.yaml --out runs/team3

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "cvslam/io/command_line.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/agent_node.h"
#include "cvslam/lcm/dc_link.h"
#include "cvslam/sim/scenario.h"
#include "cvslam/slam/agent_calibration.h"
#include "cvslam/simrun/scenario_calibration.h"
#include "cvslam/slam/visual_slam_pipeline.h"
#include "cvslam/vision/vocabulary.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage =
    R"(usage: cvslam_agent --id N (--scenario FILE | --calibration DIR) [options]

One UAV of the team as a process: subscribes UAV<N>/IMU, UAV<N>/FEATURES or UAV<N>/STEREO
and UAV<N>/GT (cvslam_replay), runs its VSLAM, publishes UAV<N>/POSE per frame,
TEAM/SUMMARY (heartbeat with receive counters) and UAV<N>/STATUS (lockstep), cooperates
with every peer it hears in DC mode, and writes DIR/agent_<N>/ (docs/run_format.md)
periodically and on exit (SIGINT/SIGTERM).

options:
  --id N                  this UAV's id (≥ 1)                                   [required]
  --scenario FILE         calibration, IMU noise and initial estimate of agent N of a
                          simulated scenario (as cvslam_run builds them)
  --calibration DIR       EuRoC folder (DIR/mav0 or DIR): cam0/cam1/imu0 sensor.yaml; the
                          filter starts at the first UAV<N>/GT pose
  --config FILE           agent configuration (default: config/agent.yaml of the source tree)
  --mode single|dc        single: alone; dc: decentralised cooperation (default single)
  --filter ekf|nhinf      overrides filter.type of the configuration
  --map knearest|full     overrides map.kind of the configuration
  --detector NAME         images: overrides frontend.detector.type (adaptive_sift | sift | orb)
  --lcm-url URL           LCM provider (default udpm://239.255.76.67:7667?ttl=0)
  --out DIR               run record folder (none if not given)
  --seed N                scenario: overrides its seed (as given to cvslam_replay)
  --duration S            scenario: simulate only the first S seconds (as cvslam_replay)
  --idle-exit S           exit after S seconds without sensor data (default: never)
  --verbose               more messages on stderr
  -h, --help              this text
)";

std::atomic<bool> g_stop{false};
void onSignal(int) {
  g_stop = true;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "cvslam_agent: %s\n", message.c_str());
  return 2;
}

struct Args {
  int id = 0;
  std::string scenario, calibration, config, mode = "single", filter, map, detector, url, out;
  long long seed = -1;
  double duration = -1.0, idle_exit = 0.0;
  bool verbose = false;
};

bool parseArgs(int argc, char** argv, Args* a, std::string* error) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](std::string* out) { return cvslam::nextArgValue(argc, argv, &i, out, error); };
    std::string v;
    double x = 0.0;
    if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (arg == "--scenario") {
      if (!value(&a->scenario)) return false;
    } else if (arg == "--calibration") {
      if (!value(&a->calibration)) return false;
    } else if (arg == "--config") {
      if (!value(&a->config)) return false;
    } else if (arg == "--mode") {
      if (!value(&a->mode)) return false;
    } else if (arg == "--filter") {
      if (!value(&a->filter)) return false;
    } else if (arg == "--map") {
      if (!value(&a->map)) return false;
    } else if (arg == "--detector") {
      if (!value(&a->detector)) return false;
    } else if (arg == "--lcm-url") {
      if (!value(&a->url)) return false;
    } else if (arg == "--out") {
      if (!value(&a->out)) return false;
    } else if (arg == "--verbose") {
      a->verbose = true;
    } else if (arg == "--id" || arg == "--seed" || arg == "--duration" || arg == "--idle-exit") {
      if (!value(&v) || !cvslam::parseNumberArg(arg, v, &x, error)) return false;
      if (arg == "--id") {
        if (x < 1 || x != std::floor(x) || x > 1e6)
          return (*error = "--id must be an integer ≥ 1"), false;
        a->id = static_cast<int>(x);
      } else if (arg == "--seed") {
        if (x < 0 || x != std::floor(x)) return (*error = "--seed must be an integer ≥ 0"), false;
        a->seed = static_cast<long long>(x);
      } else if (arg == "--duration") {
        if (x <= 0) return (*error = "--duration must be > 0"), false;
        a->duration = x;
      } else {
        if (x <= 0) return (*error = "--idle-exit must be > 0"), false;
        a->idle_exit = x;
      }
    } else {
      return (*error = "unknown option '" + arg + "' (try --help)"), false;
    }
  }
  if (a->id == 0) return (*error = "--id is required (try --help)"), false;
  if (a->scenario.empty() == a->calibration.empty())
    return (*error = "give exactly one of --scenario and --calibration (try --help)"), false;
  if (a->mode != "single" && a->mode != "dc")
    return (*error = "--mode must be single or dc, not '" + a->mode + "'"), false;
  if (!a->calibration.empty() && (a->seed >= 0 || a->duration > 0))
    return (*error = "--seed and --duration need --scenario"), false;
  return true;
}

/// Applies `key: value` to an options struct through its loader (overrides from the command
/// line get the same validation as the file).
template <typename T>
Status override(T& target, const std::string& key, const std::string& value,
                const std::string& what) {
  auto cfg = cvslam::ConfigNode::fromString(key + ": " + value, what);
  if (!cfg.ok()) return cfg.status();
  target.load(*cfg);
  return cfg->status();
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  std::string error;
  if (!parseArgs(argc, argv, &args, &error)) return fail(error);

  std::string config_path = args.config;
  if (config_path.empty() && std::filesystem::exists(CVSLAM_CONFIG_DIR "/agent.yaml"))
    config_path = CVSLAM_CONFIG_DIR "/agent.yaml";
  cvslam::VisualInertialSlamOptions options;
  cvslam::VisualFrontEndOptions frontend;
  cvslam::transport::AgentNodeOptions node;
  cvslam::coop::DcCooperationOptions coop_options;
  if (!config_path.empty()) {
    auto cfg = cvslam::ConfigNode::loadFile(config_path);
    if (!cfg.ok()) return fail(cfg.status().message());
    options.load(*cfg);
    frontend.load(cfg->child("frontend"));
    node.load(cfg->child("agent"));
    coop_options.load(cfg->child("coop"));
    cfg->child("lcm");
    if (Status s = cfg->finish(); !s.ok()) return fail(s.message());
  }
  if (!args.filter.empty())
    if (Status s = override(options.filter, "type", args.filter, "--filter"); !s.ok())
      return fail(s.message());
  if (!args.map.empty())
    if (Status s = override(options.map, "kind", args.map, "--map"); !s.ok())
      return fail(s.message());
  if (!args.detector.empty())
    if (Status s = override(frontend.front_end.detector, "type", args.detector, "--detector");
        !s.ok())
      return fail(s.message());
  if (auto p = options.filter.policy(); !p.ok()) return fail(p.status().message());

  // Calibration: a scenario (as cvslam_run) or an EuRoC folder.
  cvslam::Expected<cvslam::AgentCalibration> calibration = Status::Error("no calibration");
  if (!args.scenario.empty()) {
    auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
    if (!scenario.ok()) return fail(scenario.status().message());
    if (args.seed >= 0) scenario->seed = static_cast<uint64_t>(args.seed);
    if (args.duration > 0) scenario->duration = std::min(scenario->duration, args.duration);
    calibration = cvslam::calibrationFromScenario(*scenario, args.id, options);
  } else {
    calibration = cvslam::calibrationFromEuroc(args.calibration, options);
  }
  if (!calibration.ok()) return fail(calibration.status().message());

  // The image path (used when UAV<N>/STEREO arrives), with the feature-index vocabulary.
  auto vocabulary = cvslam::loadFeatureIndexVocabulary(
      frontend, std::filesystem::path(config_path).parent_path().string());
  if (!vocabulary.ok()) return fail(vocabulary.status().message());
  auto images = cvslam::VisualSlamPipeline::create(frontend, calibration->camera, *vocabulary);
  if (!images.ok()) return fail(images.status().message());

  node.id = args.id;
  node.mode = args.mode;
  node.out_dir = args.out;
  node.idle_exit_s = args.idle_exit;
  node.verbose = args.verbose;
  node.filter_name = options.filter.type == cvslam::FilterType::kEkf ? "ekf" : "nhinf";
  if (!args.url.empty()) node.url = args.url;
  std::random_device entropy;
  node.boot_id = (static_cast<int64_t>(entropy()) << 31) ^ static_cast<int64_t>(entropy()) ^
                 static_cast<int64_t>(getpid());

  std::unique_ptr<cvslam::transport::CooperationLink> coop;
  if (args.mode == "dc") {
    coop =
        std::make_unique<cvslam::transport::DcLink>(args.id, coop_options, node.boot_id, args.out);
  }

  if (!args.out.empty()) {
    cvslam::RunInfo info;
    info.mode = args.mode;
    info.filter = node.filter_name;
    info.map = options.map.kind == cvslam::MapKind::kFull ? "full" : "knearest";
    info.scenario = args.scenario.empty() ? args.calibration : args.scenario;
    if (!std::filesystem::exists(args.out + "/run.json"))
      if (Status s = cvslam::writeRunInfo(args.out, info); !s.ok()) return fail(s.message());
  }

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  auto agent = cvslam::transport::AgentNode::create(node, std::move(*calibration),
                                                    std::move(*images), std::move(coop));
  if (!agent.ok()) return fail(agent.status().message());
  if (args.verbose)
    std::fprintf(stderr, "cvslam_agent %d: %s mode, boot id %lld, listening\n", args.id,
                 args.mode.c_str(), static_cast<long long>(node.boot_id));
  Status s = (*agent)->run(g_stop);
  std::printf("cvslam_agent: %s\n", (*agent)->report().c_str());
  if (!s.ok()) return fail(s.message());
  return 0;
}
