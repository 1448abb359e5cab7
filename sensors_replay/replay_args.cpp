#include "replay_args.h"

#include <cstdio>
#include <cstdlib>
#include <set>

#include "cvslam/core/status.h"
#include "cvslam/io/cli.h"

namespace cvslam::replay {

const char* const kUsage =
    R"(usage: cvslam_replay (--scenario FILE | --dataset ID:PATH ... | --log FILE) [options]

Publishes sensor data over LCM: per UAV, UAV<id>/IMU (imu_t), UAV<id>/GT (pose_t),
UAV<id>/STEREO (stereo_image_t; mono8, PNG with --compress) or, for feature-only
simulation, UAV<id>/FEATURES (stereo_features_t). header.utime = dataset time,
header.agent_id = -1 (replay), header.seq per channel.
Several datasets play on one clock: each starts at its first timestamp.

source (one of):
  --scenario FILE       simulate the scenario live (rendered images by default)
  --dataset ID:PATH     EuRoC ASL folder (holding mav0/) played as UAV ID; repeat
  --log FILE            an LCM log of a team run (lcm-logger): its sensor channels (UAV<id>/
                        IMU, GT, FEATURES, STEREO) played again, e.g. in lockstep into fresh
                        agents; everything else in the log is skipped
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
  --agents LIST         play only these UAVs, e.g. 2 (one replay per vehicle, docs/transport.md)
  --start-at T          begin at wall time T (Unix seconds, e.g. $(date +%s) + 2), so that
                        replays on several hosts play on one clock
  --start S             skip the first S s of play time
  --duration S          play only S s (from --start)
  --camera-time-offset S  folders: a frame stamped t was taken at IMU time t + S (a
                        constant camera-IMU clock offset, Kalibr's timeshift_cam_imu;
                        default 0); frames are played at the corrected time
  --compress            stereo images as PNG
  --no-gt               do not publish UAV<id>/GT
  --sensing KIND        scenario: images (default) | features (no rendering)
  --world KIND          scenario: aerial | hall (default: the scenario's render: world,
                        else hall for TUM trajectories and aerial otherwise)
  --seed N              scenario: override the seed
  --quiet               no progress or summary output
  -h, --help            this text
Ctrl-C (SIGINT/SIGTERM) stops after the current message.
)";

namespace {

/// ID:PATH of --dataset, ID a whole number ≥ 1.
Status parseDataset(const std::string& v, DatasetArg& d) {
  const auto colon = v.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == v.size())
    return Status::Error("--dataset wants ID:PATH, got '" + v + "'");
  const std::string id = v.substr(0, colon);
  char* end = nullptr;
  const long n = std::strtol(id.c_str(), &end, 10);
  if (*end != '\0' || n < 1 || n > 1000000)
    return Status::Error("--dataset: bad UAV id in '" + v + "' (want an integer >= 1)");
  d.id = static_cast<int>(n);
  d.path = v.substr(colon + 1);
  return Status::Ok();
}

/// What CLI11 cannot say per option: the source, distinct UAV ids, scenario-only options.
Status checkArgs(const std::vector<std::string>& datasets, Args& a) {
  const int sources =
      (a.scenario.empty() ? 0 : 1) + (datasets.empty() ? 0 : 1) + (a.log.empty() ? 0 : 1);
  if (sources != 1) return Status::Error("give one of --scenario, --dataset or --log (see --help)");
  std::set<int> ids;
  for (const std::string& text : datasets) {
    DatasetArg d;
    if (Status s = parseDataset(text, d); !s.ok()) return s;
    if (!ids.insert(d.id).second)
      return Status::Error("--dataset: UAV id " + std::to_string(d.id) + " given twice");
    a.datasets.push_back(d);
  }
  if (a.scenario.empty() && (a.sensing != "images" || !a.world.empty() || a.seed >= 0))
    return Status::Error("--sensing, --world and --seed apply to --scenario only");
  return Status::Ok();
}

}  // namespace

std::optional<int> parseArgs(int argc, char** argv, Args& a) {
  std::vector<std::string> datasets;
  CLI::App app("publishes sensor data over LCM", "cvslam_replay");
  auto* scenario = app.add_option("--scenario", a.scenario);
  app.add_option("--dataset", datasets)->excludes(scenario)->allow_extra_args(false);
  app.add_option("--log", a.log);
  app.add_option("--agents", a.agents)->delimiter(',')->allow_extra_args(false);
  app.add_option("--start-at", a.start_at)->check(cli::kPositive);
  auto* rate = app.add_option("--rate", a.rate)->check(cli::kNonNegative);
  auto* fast = app.add_flag("--fast");
  app.add_flag("--lockstep", a.lockstep)->excludes(rate)->excludes(fast);
  app.add_option("--participants", a.participants)->delimiter(',')->allow_extra_args(false);
  app.add_option("--lockstep-timeout", a.lockstep_timeout)->check(cli::kPositive);
  app.add_option("--lcm-url", a.lcm_url);
  app.add_option("--start", a.start)->check(cli::kNonNegative);
  app.add_option("--duration", a.duration)->check(cli::kFinite);
  app.add_option("--camera-time-offset", a.camera_time_offset)->check(cli::kFinite);
  app.add_flag("--compress", a.compress);
  app.add_flag("--no-gt", a.no_gt);
  app.add_option("--sensing", a.sensing)->check(CLI::IsMember({"images", "features"}));
  app.add_option("--world", a.world);
  app.add_option("--seed", a.seed)->check(cli::kCount);
  app.add_flag("--quiet", a.quiet);
  if (auto exit_code = cli::parse(app, argc, argv, kUsage)) return exit_code;
  if (fast->count() > 0) a.rate = 0.0;
  if (Status s = checkArgs(datasets, a); !s.ok()) {
    std::fprintf(stderr, "cvslam_replay: %s\n", s.message().c_str());
    return 2;
  }
  return std::nullopt;
}

}  // namespace cvslam::replay
