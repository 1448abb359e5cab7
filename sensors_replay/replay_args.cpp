#include "replay_args.h"

#include <set>
#include <sstream>

namespace cvslam::replay {

const char* const kUsage =
    R"(usage: cvslam_replay (--scenario FILE | --dataset ID:PATH ...) [options]

Publishes sensor data over LCM: per UAV, UAV<id>/IMU (imu_t), UAV<id>/GT (pose_t),
UAV<id>/STEREO (stereo_image_t; mono8, PNG with --compress) or, for feature-only
simulation, UAV<id>/FEATURES (stereo_features_t). header.utime = dataset time,
header.agent_id = -1 (replay), header.seq per channel.
Several datasets play on one clock: each starts at its first timestamp.

source (one of):
  --scenario FILE       simulate the scenario live (rendered images by default)
  --dataset ID:PATH     EuRoC ASL folder (holding mav0/) played as UAV ID; repeat
pace (one of):
  --rate R              R × real time (default 1); 0 = as fast as possible
  --fast                same as --rate 0
  --lockstep            publish epoch k+1 only after every participant reported on
                        UAV<id>/STATUS processed_utime >= the last utime sent to it
                        in epoch k (docs/replay.md); participants must first send one
                        STATUS to announce themselves
  --participants LIST   lockstep participants, e.g. 1,2,3,0 (default: the UAVs played)
  --lockstep-timeout S  give up (exit 2) after S s without acknowledgement (default 60)
options:
  --lcm-url URL         LCM provider (default udpm://239.255.76.67:7667?ttl=0)
  --start S             skip the first S s of play time
  --duration S          play only S s (from --start)
  --compress            stereo images as PNG
  --no-gt               do not publish UAV<id>/GT
  --sensing KIND        scenario: images (default) | features (no rendering)
  --world KIND          scenario: aerial | hall (default: hall for TUM trajectories)
  --seed N              scenario: override the seed
  --quiet               no progress or summary output
  -h, --help            this text
Ctrl-C (SIGINT/SIGTERM) stops after the current message.
)";

namespace {

Status parseList(const std::string& text, std::vector<int>& out) {
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    try {
      std::size_t used = 0;
      out.push_back(std::stoi(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      return Status::Error("bad id '" + item + "' in --participants");
    }
  }
  return Status::Ok();
}

}  // namespace

Status parseArgs(int argc, char** argv, Args& a, bool& help) {
  bool rate_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      help = true;
      return Status::Ok();
    }
    if (arg == "--fast" || arg == "--lockstep" || arg == "--compress" || arg == "--no-gt" ||
        arg == "--quiet") {
      if (arg == "--fast") {
        a.rate = 0.0;
        rate_given = true;
      }
      if (arg == "--lockstep") a.lockstep = true;
      if (arg == "--compress") a.compress = true;
      if (arg == "--no-gt") a.no_gt = true;
      if (arg == "--quiet") a.quiet = true;
      continue;
    }
    if (i + 1 >= argc) return Status::Error(arg + " needs a value (see --help)");
    const std::string v = argv[++i];
    try {
      if (arg == "--scenario") {
        a.scenario = v;
      } else if (arg == "--dataset") {
        const auto colon = v.find(':');
        std::size_t used = 0;
        DatasetArg d;
        if (colon == std::string::npos || colon == 0 || colon + 1 == v.size())
          return Status::Error("--dataset wants ID:PATH, got '" + v + "'");
        d.id = std::stoi(v.substr(0, colon), &used);
        if (used != colon || d.id < 1)
          return Status::Error("--dataset: bad UAV id in '" + v + "' (want an integer >= 1)");
        d.path = v.substr(colon + 1);
        a.datasets.push_back(d);
      } else if (arg == "--rate") {
        a.rate = std::stod(v);
        rate_given = true;
      } else if (arg == "--participants") {
        Status s = parseList(v, a.participants);
        if (!s.ok()) return s;
      } else if (arg == "--lockstep-timeout") {
        a.lockstep_timeout = std::stod(v);
      } else if (arg == "--lcm-url") {
        a.lcm_url = v;
      } else if (arg == "--start") {
        a.start = std::stod(v);
      } else if (arg == "--duration") {
        a.duration = std::stod(v);
      } else if (arg == "--sensing") {
        a.sensing = v;
      } else if (arg == "--world") {
        a.world = v;
      } else if (arg == "--seed") {
        a.seed = std::stoll(v);
      } else {
        return Status::Error("unknown option " + arg + " (see --help)");
      }
    } catch (const std::exception&) {
      return Status::Error("bad number for " + arg + ": '" + v + "'");
    }
  }
  if (a.scenario.empty() == a.datasets.empty())
    return Status::Error("give either --scenario or --dataset (see --help)");
  std::set<int> ids;
  for (const auto& d : a.datasets) {
    if (!ids.insert(d.id).second)
      return Status::Error("--dataset: UAV id " + std::to_string(d.id) + " given twice");
  }
  if (a.lockstep && rate_given) return Status::Error("--lockstep excludes --rate/--fast");
  if (a.rate < 0.0) return Status::Error("--rate must be >= 0");
  if (a.start < 0.0) return Status::Error("--start must be >= 0");
  if (a.lockstep_timeout <= 0.0) return Status::Error("--lockstep-timeout must be > 0");
  if (a.sensing != "images" && a.sensing != "features")
    return Status::Error("--sensing must be images or features");
  if (!a.datasets.empty() && (a.sensing != "images" || !a.world.empty() || a.seed >= 0))
    return Status::Error("--sensing, --world and --seed apply to --scenario only");
  return Status::Ok();
}

}  // namespace cvslam::replay
