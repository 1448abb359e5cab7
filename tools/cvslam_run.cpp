// cvslam_run — runs every UAV of a scenario in one process, deterministically, without any
// transport (docs/architecture.md, docs/run_format.md), and writes the run record of docs/run_format.md.
//
//   cvslam_run --scenario config/scenarios/thesis_loop.yaml --mode single --out runs/loop

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/command_line.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/sim/scenario.h"
#include "cvslam/simrun/rendered_sensing.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "dc_team_link.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage = R"(usage: cvslam_run --scenario FILE --out DIR [options]

Runs every UAV of a simulated scenario in one process (no LCM) and writes
DIR/agent_<id>/{trajectory.tum, ins_trajectory.tum, states.csv, truth.csv,
landmarks.csv, stats.json, events.csv[, frontend.csv]} and DIR/run.json
(docs/run_format.md).

options:
  --scenario FILE         scenario YAML (config/scenarios/*.yaml)               [required]
  --out DIR               output folder (created)                               [required]
  --config FILE           agent configuration (default: config/agent.yaml of the
                          source tree, else built-in defaults)
  --mode single|dc        single: every UAV alone; dc: decentralised cooperation
                          (thesis §6.6; LCM-encoded messages through an in-process
                          mailbox, configuration section `coop:`, docs/cooperation.md)
  --ci METHOD             dc: overrides coop.ci_method (adaptive | fast |
                          optimal_trace | optimal_determinant | optimal_vehicle)
  --both-ways             dc: overrides coop.both_ways to true (the default)
  --one-way               dc: overrides coop.both_ways to false (thesis §6.6.5: only the
                          UAV that receives the indices fuses)
  --sensing KIND          features: feature-level simulation with true landmark ids;
                          images: stereo pairs rendered at the true pose (the scenario's
                          `render:` world, default aerial) through the real front end and
                          map association (configuration section `frontend:`)
  --world aerial|hall     images: overrides the scenario's render world kind
  --detector NAME         images: overrides frontend.detector.type (adaptive_sift |
                          fast_sift | sift | orb)
  --filter ekf|nhinf      overrides filter.type of the configuration
  --map knearest|full     overrides map.kind of the configuration
  --passes N              overrides slam.observation_passes (thesis §5.7.3)
  --pixel-noise KIND      overrides every UAV's pixel noise kind: gaussian |
                          non_gaussian_centred | non_centred (thesis §5.9)
  --seed N                overrides the scenario's seed
  --duration S            simulate only the first S seconds
  --agents ID[,ID...]     run only these UAVs of the scenario (their seeds unchanged)
  --quiet                 no progress output
  -h, --help              this text
)";

struct Args {
  std::string scenario, out, config, mode = "single", sensing = "features", filter, map;
  std::string pixel_noise, world, detector, ci, agents;
  std::optional<bool> both_ways;
  int passes = 0;
  long long seed = -1;
  double duration = -1.0;
  bool quiet = false;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "cvslam_run: %s\n", message.c_str());
  return 2;
}

bool parseArgs(int argc, char** argv, Args* a, std::string* error) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](std::string* out) { return cvslam::nextArgValue(argc, argv, &i, out, error); };
    std::string v;
    if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (arg == "--scenario") {
      if (!value(&a->scenario)) return false;
    } else if (arg == "--out") {
      if (!value(&a->out)) return false;
    } else if (arg == "--config") {
      if (!value(&a->config)) return false;
    } else if (arg == "--mode") {
      if (!value(&a->mode)) return false;
    } else if (arg == "--sensing") {
      if (!value(&a->sensing)) return false;
    } else if (arg == "--filter") {
      if (!value(&a->filter)) return false;
    } else if (arg == "--map") {
      if (!value(&a->map)) return false;
    } else if (arg == "--world") {
      if (!value(&a->world)) return false;
    } else if (arg == "--detector") {
      if (!value(&a->detector)) return false;
    } else if (arg == "--pixel-noise") {
      if (!value(&a->pixel_noise)) return false;
    } else if (arg == "--ci") {
      if (!value(&a->ci)) return false;
    } else if (arg == "--both-ways" || arg == "--one-way") {
      if (a->both_ways && *a->both_ways != (arg == "--both-ways")) {
        return (*error = "--both-ways and --one-way exclude each other"), false;
      }
      a->both_ways = arg == "--both-ways";
    } else if (arg == "--agents") {
      if (!value(&a->agents)) return false;
    } else if (arg == "--quiet") {
      a->quiet = true;
    } else if (arg == "--passes" || arg == "--seed" || arg == "--duration") {
      double x = 0.0;
      if (!value(&v) || !cvslam::parseNumberArg(arg, v, &x, error)) return false;
      if (arg == "--passes") {
        if (x < 1 || x != std::floor(x)) return (*error = "--passes must be an integer ≥ 1"), false;
        a->passes = static_cast<int>(x);
      } else if (arg == "--seed") {
        if (x < 0 || x != std::floor(x)) return (*error = "--seed must be an integer ≥ 0"), false;
        a->seed = static_cast<long long>(x);
      } else {
        if (x <= 0) return (*error = "--duration must be > 0"), false;
        a->duration = x;
      }
    } else {
      *error = "unknown option '" + arg + "' (try --help)";
      return false;
    }
  }
  if (a->scenario.empty()) return (*error = "--scenario is required (try --help)"), false;
  if (a->out.empty()) return (*error = "--out is required (try --help)"), false;
  if (a->mode != "single" && a->mode != "dc") {
    return (*error = "--mode " + a->mode + " is not available (single or dc)"), false;
  }
  if (a->mode != "dc" && (!a->ci.empty() || a->both_ways)) {
    return (*error = "--ci, --both-ways and --one-way need --mode dc"), false;
  }
  if (a->sensing != "features" && a->sensing != "images") {
    return (*error = "--sensing must be features or images, not '" + a->sensing + "'"), false;
  }
  if (a->sensing != "images" && (!a->world.empty() || !a->detector.empty())) {
    return (*error = "--world and --detector need --sensing images"), false;
  }
  return true;
}

/// Per-UAV outputs and counters.
struct AgentOutput {
  std::unique_ptr<cvslam::AgentRunWriter> writer;
  std::ofstream events;
  std::ofstream frontend;
  int frames = 0;
  double first_loop_t = -1.0;
  double cpu_ms = 0.0;
};

Eigen::Matrix<double, 9, 1> truthVector(const cvslam::sim::GroundTruth& g) {
  Eigen::Matrix<double, 9, 1> x;
  x << g.p_BinN, g.v_B, g.euler;
  return x;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  std::string error;
  if (!parseArgs(argc, argv, &args, &error)) return fail(error);

  auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
  if (!scenario.ok()) return fail(scenario.status().message());
  if (args.seed >= 0) scenario->seed = static_cast<uint64_t>(args.seed);
  if (args.duration > 0) scenario->duration = std::min(scenario->duration, args.duration);
  if (!args.agents.empty()) {
    // A subset of the team (faster experiments); each agent keeps its own RNG streams.
    std::vector<cvslam::sim::AgentSpec> chosen;
    std::stringstream list(args.agents);
    for (std::string item; std::getline(list, item, ',');) {
      char* end = nullptr;
      const long id = std::strtol(item.c_str(), &end, 10);
      auto it = std::find_if(scenario->agents.begin(), scenario->agents.end(),
                             [&](const cvslam::sim::AgentSpec& a) { return a.id == id; });
      if (item.empty() || *end != '\0' || it == scenario->agents.end()) {
        return fail("--agents: no agent '" + item + "' in the scenario");
      }
      chosen.push_back(*it);
    }
    scenario->agents = chosen;
  }
  if (!args.pixel_noise.empty()) {
    auto cfg = cvslam::ConfigNode::fromString("kind: " + args.pixel_noise, "--pixel-noise");
    for (cvslam::sim::AgentSpec& agent : scenario->agents) agent.pixel_noise.load(*cfg);
    if (!cfg->status().ok()) return fail(cfg->status().message());
  }

  // Agent configuration: the file given, else the source tree's default, else defaults.
  std::string config_path = args.config;
  if (config_path.empty() && std::filesystem::exists(CVSLAM_CONFIG_DIR "/agent.yaml")) {
    config_path = CVSLAM_CONFIG_DIR "/agent.yaml";
  }
  cvslam::VisualInertialSlamOptions options;
  cvslam::VisualFrontEndOptions frontend;
  cvslam::coop::DcCooperationOptions coop_options;
  if (!config_path.empty()) {
    auto cfg = cvslam::ConfigNode::loadFile(config_path);
    if (!cfg.ok()) return fail(cfg.status().message());
    options.load(*cfg);
    frontend.load(cfg->child("frontend"));
    coop_options.load(cfg->child("coop"));
    for (const char* section : {"agent", "lcm"}) cfg->skip(section);
    if (Status s = cfg->finish(); !s.ok()) return fail(s.message());
  }
  if (!args.world.empty()) {
    auto cfg = cvslam::ConfigNode::fromString("kind: " + args.world, "--world");
    scenario->render_world.load(*cfg);
    if (!cfg->status().ok()) return fail(cfg->status().message());
  }
  if (!args.detector.empty()) {
    auto cfg = cvslam::ConfigNode::fromString("type: " + args.detector, "--detector");
    frontend.front_end.detector.load(*cfg);
    if (!cfg->status().ok()) return fail(cfg->status().message());
  }
  if (!args.filter.empty()) {
    auto cfg = cvslam::ConfigNode::fromString("type: " + args.filter, "--filter");
    options.filter.load(*cfg);
    if (!cfg->status().ok()) return fail(cfg->status().message());
  }
  if (!args.map.empty()) {
    auto cfg = cvslam::ConfigNode::fromString("kind: " + args.map, "--map");
    options.map.load(*cfg);
    if (!cfg->status().ok()) return fail(cfg->status().message());
  }
  if (args.passes > 0) options.slam.observation_passes = args.passes;
  if (!args.ci.empty()) {
    auto method = cvslam::coop::parseCiMethod(args.ci);
    if (!method.ok()) return fail(method.status().message());
    coop_options.ci_method = *method;
  }
  if (args.both_ways) coop_options.both_ways = *args.both_ways;
  coop_options.true_ids = args.sensing == "features";
  if (auto p = options.filter.policy(); !p.ok()) return fail(p.status().message());

  cvslam::SimulatedTeamRun::SensingFactory sensing;
  if (args.sensing == "images") {
    // The feature index needs a vocabulary of the detector's descriptor type (§6.6.3).
    auto vocabulary = cvslam::loadFeatureIndexVocabulary(
        frontend, std::filesystem::path(config_path).parent_path().string());
    if (!vocabulary.ok()) return fail(vocabulary.status().message());
    auto factory = cvslam::makeRenderedSensingFactory(*scenario, frontend, *vocabulary);
    if (!factory.ok()) return fail(factory.status().message());
    sensing = *factory;
  }
  auto team = cvslam::SimulatedTeamRun::create(*scenario, options, sensing);
  if (!team.ok()) return fail(team.status().message());
  cvslam::SimulatedTeamRun& run = **team;

  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return fail("cannot create " + args.out + ": " + ec.message());
  std::map<int, AgentOutput> outputs;
  for (std::size_t i = 0; i < run.agentCount(); ++i) {
    const int id = run.agentId(i);
    AgentOutput& o = outputs[id];
    o.writer = std::make_unique<cvslam::AgentRunWriter>();
    if (Status s = o.writer->open(args.out, id); !s.ok()) return fail(s.message());
    o.events.open(cvslam::agentDir(args.out, id) + "/events.csv");
    if (!o.events) return fail("cannot write " + cvslam::agentDir(args.out, id) + "/events.csv");
    o.events << "t,observations,updated,rejected,initialised,archived,reactivated,"
                "loop_landmarks,loop_closure,theta_reduced,state_size\n";
    if (args.sensing == "images") {
      o.frontend.open(cvslam::agentDir(args.out, id) + "/frontend.csv");
      if (!o.frontend) return fail("cannot write frontend.csv of agent " + std::to_string(id));
      o.frontend << "t,observations,predictions,gated_pairs,associated,initialised,front_end_ms,"
                    "association_ms,filter_ms,loop_candidates,loop_inliers\n";
    }
  }

  std::unique_ptr<cvslam::DcTeamLink> dc;
  if (args.mode == "dc") {
    std::vector<int> ids;
    for (std::size_t i = 0; i < run.agentCount(); ++i) ids.push_back(run.agentId(i));
    dc = std::make_unique<cvslam::DcTeamLink>(coop_options, ids);
    if (Status s = dc->open(args.out); !s.ok()) return fail(s.message());
  }

  const double duration = scenario->duration;
  int next_progress = 10;
  const auto wall_start = std::chrono::steady_clock::now();
  Status run_status = run.run([&](const cvslam::SimulatedFrame& f) -> Status {
    AgentOutput& o = outputs[f.agent_id];
    if (dc) {
      if (Status s = dc->afterFrame(f, o.writer.get()); !s.ok()) return s;
    }
    const cvslam::FrameReport& report = *f.report;
    const double t = static_cast<double>(f.t_us) * 1e-6;
    double frame_ms = f.time_ms;
    if (const auto* rs = dynamic_cast<const cvslam::RenderedSensing*>(f.sensing)) {
      // Frame time of the agent's own work (front end, association, filter), not rendering.
      const cvslam::VisualFrameResult& r = rs->lastResult();
      frame_ms = r.front_end_ms + r.association_ms + r.filter_ms;
      o.frontend << t << ',' << r.frame.observations.size() << ',' << r.predictions << ','
                 << r.association.candidates_gated << ',' << r.association.associated << ','
                 << r.initialised.size() << ',' << r.front_end_ms << ',' << r.association_ms << ','
                 << r.filter_ms << ',' << r.loop.candidates << ',' << r.loop.inliers << '\n';
    }
    o.cpu_ms += frame_ms;
    ++o.frames;
    if (report.loop_closure && o.first_loop_t < 0) o.first_loop_t = t;

    const Eigen::VectorXd x = f.slam->vehicleState();
    const Eigen::MatrixXd P = f.slam->vehicleCovariance();
    if (Status s = o.writer->addState(t, x.head<9>(), P.topLeftCorner<9, 9>()); !s.ok()) return s;
    if (Status s = o.writer->addTruth(t, truthVector(*f.truth)); !s.ok()) return s;
    if (Status s = o.writer->addInsState(t, f.x_ins->head<9>()); !s.ok()) return s;
    cvslam::FrameStats fs;
    fs.t = t;
    fs.time_ms = frame_ms;
    fs.state_size = report.state_size;
    fs.landmarks = report.landmarks_in_state;
    double sigma_sum = 0.0;
    int n_lm = 0;
    for (const cvslam::StateVariable& v : f.slam->state().variables()) {
      if (v.key.kind != cvslam::VariableKey::Kind::kLandmark) continue;
      sigma_sum += std::sqrt(f.slam->state().covarianceOf(v).trace() / 3.0);
      ++n_lm;
    }
    if (n_lm > 0) fs.landmark_sigma_mean_m = sigma_sum / n_lm;
    o.writer->addFrame(fs);
    o.events << t << ',' << report.observations << ',' << report.updated << ',' << report.rejected
             << ',' << report.initialised << ',' << report.archived << ',' << report.reactivated
             << ',' << report.loop_landmarks << ',' << (report.loop_closure ? 1 : 0) << ','
             << (report.theta_reduced ? 1 : 0) << ',' << report.state_size << '\n';
    if (!args.quiet && t >= duration * next_progress / 100.0) {
      std::fprintf(stderr, "cvslam_run: %3d%%  t = %.0f s\n", next_progress, t);
      next_progress += 10;
    }
    return Status::Ok();
  });
  if (!run_status.ok()) return fail(run_status.message());
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  // True landmark positions for the map's error columns: the true id (features) or the
  // surface the renderer showed where the landmark was initialised (images).
  for (std::size_t i = 0; i < run.agentCount(); ++i) {
    AgentOutput& o = outputs[run.agentId(i)];
    std::vector<cvslam::LandmarkRecord> records;
    for (const cvslam::MapLandmark& m : run.slam(i).map()) {
      cvslam::LandmarkRecord r;
      r.id = m.id;
      r.p_LinN = m.p_LinN;
      r.var = m.covariance.diagonal();
      Eigen::Vector3d p_true;
      if (run.sensing(i).landmarkTruth(m.id, &p_true)) r.truth = p_true;
      records.push_back(r);
    }
    if (Status s = o.writer->writeLandmarks(records); !s.ok()) return fail(s.message());
    if (Status s = o.writer->close(); !s.ok()) return fail(s.message());
  }
  cvslam::RunInfo info;
  info.mode = args.mode;
  info.filter = options.filter.type == cvslam::FilterType::kEkf ? "ekf" : "nhinf";
  info.map = options.map.kind == cvslam::MapKind::kFull ? "full" : "knearest";
  info.scenario = args.scenario;
  if (Status s = cvslam::writeRunInfo(args.out, info); !s.ok()) return fail(s.message());

  std::printf("cvslam_run: %s, %s, map %s, %.0f s simulated in %.1f s wall (%.1fx real time)\n",
              scenario->name.c_str(), info.filter.c_str(), info.map.c_str(), duration, wall_s,
              duration / std::max(wall_s, 1e-9));
  for (std::size_t i = 0; i < run.agentCount(); ++i) {
    const AgentOutput& o = outputs[run.agentId(i)];
    const cvslam::FilterStatistics& st = run.slam(i).statistics();
    const std::string loop =
        o.first_loop_t >= 0 ? "first at " + std::to_string(static_cast<int>(o.first_loop_t)) + " s"
                            : "none";
    std::printf(
        "  UAV%d: %d frames, %.2f ms/frame, map %zu landmarks, loop closure %s, gated out "
        "%ld of %ld observations, θ reductions %ld\n",
        run.agentId(i), o.frames, o.frames > 0 ? o.cpu_ms / o.frames : 0.0,
        run.slam(i).map().size(), loop.c_str(), st.observations_rejected,
        st.observations_accepted + st.observations_rejected, st.theta_reductions);
    if (const auto* rs = dynamic_cast<const cvslam::RenderedSensing*>(&run.sensing(i))) {
      const cvslam::RenderedSensingStats& s = rs->stats();
      const double n = static_cast<double>(std::max(s.frames, 1L));
      std::printf(
          "        images: %.1f observations/frame; per frame: render %.1f ms, front end %.1f ms, "
          "association %.2f ms, filter %.2f ms; stereo precision %.4f (%ld checked), map "
          "association precision %.4f (%ld of %ld type-1 checked; %.4f of the %ld the filter "
          "used); disparity error of right matches mean %.3f px, RMS %.3f px; re-observed left "
          "pixel error RMS %.3f px\n",
          static_cast<double>(s.observations) / n, s.render_ms / n, s.front_end_ms / n,
          s.association_ms / n, s.filter_ms / n, s.stereoPrecision(), s.stereo_checked,
          s.associationPrecision(), s.associated_checked, s.associated,
          s.usedAssociationPrecision(), s.associated_checked - s.associated_unused_checked,
          s.disparityBias(), s.disparityRms(), s.reobservationRms());
    }
  }
  if (dc) dc->printSummary(stdout, duration);
  std::printf("  outputs in %s (evaluate with: cvslam_eval --run %s --summary-json F)\n",
              args.out.c_str(), args.out.c_str());
  return 0;
}
