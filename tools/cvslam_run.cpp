// cvslam_run — runs every UAV of a scenario in one process, deterministically, without any
// transport (docs/architecture.md, docs/run_format.md), and writes the run record of
// docs/run_format.md through the same AgentRunRecorder and DC-link core as cvslam_agent.
//
//   cvslam_run --scenario config/scenarios/thesis_loop.yaml --mode single --out runs/loop

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cc_team_link.h"
#include "cvslam/coop/agent_config.h"
#include "cvslam/io/cli.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/json_file.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/cross_uav_match_audit.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/simrun/rendered_sensing.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/agent_run_recorder.h"
#include "dc_team_link.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage = R"(usage: cvslam_run --scenario FILE --out DIR [options]

Runs every UAV of a simulated scenario in one process (no LCM) and writes
DIR/agent_<id>/{trajectory.tum, ins_trajectory.tum, states.csv, truth.csv,
landmarks.csv, stats.json, events.csv, config_used.yaml[, frontend.csv, coop.csv]}
and DIR/run.json (docs/run_format.md). config_used.yaml is the configuration as run
(file + overrides): give it back with --config to repeat the run.

options:
  --scenario FILE         scenario YAML (config/scenarios/*.yaml)               [required]
  --out DIR               output folder (created)                               [required]
  --config FILE           agent configuration (default: config/agent.yaml of the
                          source tree, else built-in defaults)
  --profile NAME          the filter profile beneath the configuration, in place of the
                          one it names: invariant_ekf (shipped) | thesis_ekf (chapter 5) |
                          ideal_ekf (with --linearise-at-truth); config/profiles/
  --set SECTION.KEY=VALUE one key of the configuration changed, e.g. map.kind=full or
                          frontend.detector.type=orb (repeatable; the rest stays as --config)
  --mode single|dc|cc     single: every UAV alone; dc: decentralised cooperation
                          (thesis §6.6; LCM-encoded messages through an in-process
                          mailbox, configuration section `coop:`, docs/cooperation.md);
                          cc: centralised cooperation (thesis §6.1–6.5): every agent runs
                          its own filter and sends its observation batches to an
                          in-process ground station (joint filter), whose estimate it
                          records; also writes DIR/ground_station/
  --gs-config FILE        cc: the ground station's options (config/ground_station.yaml);
                          default: the agents' filter/ins/map/slam sections (but the
                          joint filter's Euler angles and invariant error chart, without
                          first-estimate Jacobians or the observability constraint) and
                          `cc:` defaults (association by true ids for features, by the agents'
                          local ids for images)
  --ci METHOD             dc: overrides coop.ci_method (adaptive | fast |
                          optimal_trace | optimal_determinant | optimal_vehicle)
  --both-ways             dc: overrides coop.both_ways to true (the default)
  --one-way               dc: overrides coop.both_ways to false (thesis §6.6.5: only the
                          UAV that receives the indices fuses)
  --coop-loss PCT         dc: each message to each peer is lost with this probability
                          [%] (a lossy radio; default 0)
  --coop-loss-seed N      dc: seed of the loss draws (default 1): one seed, one pattern
  --sensing KIND          features: feature-level simulation with true landmark ids;
                          images: stereo pairs rendered at the true pose (the scenario's
                          `render:` world, else hall for TUM-trajectory scenarios and aerial
                          otherwise; the same images cvslam_replay publishes) through the
                          real front end and map association (configuration `frontend:`)
  --world aerial|hall     images: overrides the render world's kind
  --detector NAME         images: overrides frontend.detector.type (adaptive_sift |
                          fast_sift | sift | orb)
  --filter ekf|nhinf      overrides filter.type of the configuration
  --map knearest|full     overrides map.kind of the configuration
  --attitude error_state|euler
                          overrides ins.attitude (euler: the thesis's model)
  --passes N              overrides slam.observation_passes (thesis §5.7.3)
  --pixel-noise KIND      overrides every UAV's pixel noise kind: gaussian |
                          non_gaussian_centred | non_centred (thesis §5.9)
  --seed N                overrides the scenario's seed
  --duration S            simulate only the first S seconds
  --agents ID[,ID...]     run only these UAVs of the scenario (their seeds unchanged)
  --starts known|unknown  overrides every UAV's `start:` (unknown: each estimates in its
                          own frame and DC finds the relations, docs/merge.md)
  --linearise-at-truth    a consistency diagnostic (features): every UAV's filter, and
                          in cc mode the ground station's models of it, take the
                          Jacobians of propagation, stereo update and landmark
                          initialisation at the true state (the "ideal EKF",
                          docs/results/ideal_ekf.md); the residuals stay at the
                          estimate; with Euler angles (--attitude euler, implied)
                          and the additive chart; run.json says so
  --quiet                 no progress output
  -h, --help              this text
)";

struct Args {
  cvslam::AgentConfigArgs config;  // --config and the shared overrides
  std::string scenario, out, mode = "single", sensing = "features", pixel_noise, world, agents;
  std::string starts;  ///< --starts: "" (as the scenario says) | known | unknown
  std::string gs_config;
  long long seed = -1;
  double duration = -1.0;
  cvslam::DcLinkLoss coop_loss;
  bool quiet = false;
  bool linearise_at_truth = false;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "cvslam_run: %s\n", message.c_str());
  return 2;
}

/// Parses the command line; nullopt: go on, else the exit status.
std::optional<int> parseArgs(int argc, char** argv, Args* a) {
  CLI::App app("runs every UAV of a simulated scenario in one process", "cvslam_run");
  // As the hand-written loop did: an option given twice takes its last value (scripts pass
  // defaults first, the caller's extra arguments after them).
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--scenario", a->scenario)->required();
  app.add_option("--out", a->out)->required();
  app.add_option("--mode", a->mode)->check(CLI::IsMember({"single", "dc", "cc"}));
  app.add_option("--gs-config", a->gs_config);
  app.add_option("--sensing", a->sensing)->check(CLI::IsMember({"features", "images"}));
  app.add_option("--world", a->world);
  app.add_option("--pixel-noise", a->pixel_noise);
  app.add_option("--seed", a->seed)->check(cvslam::cli::kCount);
  app.add_option("--duration", a->duration)->check(cvslam::cli::kPositive);
  app.add_option("--agents", a->agents);
  app.add_option("--starts", a->starts)->check(CLI::IsMember({"known", "unknown"}));
  auto* loss = app.add_option("--coop-loss", a->coop_loss.percent)->check(CLI::Range(0.0, 100.0));
  auto* loss_seed = app.add_option("--coop-loss-seed", a->coop_loss.seed);
  app.add_flag("--quiet", a->quiet);
  app.add_flag("--linearise-at-truth", a->linearise_at_truth);
  a->config.addTo(app);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return exit_code;
  if (a->mode != "dc" && a->config.anyCoop())
    return fail("--ci, --both-ways and --one-way need --mode dc");
  if (a->mode != "dc" && (loss->count() > 0 || loss_seed->count() > 0))
    return fail("--coop-loss and --coop-loss-seed need --mode dc");
  if (a->mode != "cc" && !a->gs_config.empty()) return fail("--gs-config needs --mode cc");
  if (a->sensing != "images" && (!a->world.empty() || !a->config.detector.empty()))
    return fail("--world and --detector need --sensing images");
  // An image landmark has no true position when it is initialised: half the Jacobians at the
  // truth would be worse than none.
  if (a->linearise_at_truth && a->sensing != "features")
    return fail("--linearise-at-truth needs --sensing features");
  // The ideal EKF runs Euler angles (VisualInertialSlam refuses the error state with it).
  if (a->linearise_at_truth && a->config.attitude == "error_state")
    return fail("--linearise-at-truth needs Euler angles (--attitude euler, its default)");
  if (a->linearise_at_truth) a->config.attitude = "euler";
  return std::nullopt;
}

/// Applies --seed, --duration, --agents, --starts, --pixel-noise and --world to the scenario.
Status applyScenarioArgs(const Args& args, cvslam::sim::Scenario* scenario) {
  if (!args.starts.empty())
    if (Status s = scenario->overrideStarts(args.starts == "known"); !s.ok())
      return Status::Error("--starts: " + s.message());
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
      if (item.empty() || *end != '\0' || it == scenario->agents.end())
        return Status::Error("--agents: no agent '" + item + "' in the scenario");
      chosen.push_back(*it);
    }
    scenario->agents = chosen;
  }
  if (!args.pixel_noise.empty()) {
    auto cfg = cvslam::ConfigNode::fromString("kind: " + args.pixel_noise, "--pixel-noise");
    for (cvslam::sim::AgentSpec& agent : scenario->agents) agent.pixel_noise.load(*cfg);
    if (!cfg->status().ok()) return cfg->status();
  }
  return Status::Ok();
}

/// The agents' sensing: feature-level (empty factory) or rendered images.
cvslam::Expected<cvslam::SimulatedTeamRun::SensingFactory> makeSensing(
    const Args& args, const cvslam::sim::Scenario& scenario, const cvslam::AgentConfig& config) {
  // The world the agent processes see through cvslam_replay (render_world_choice.h); chosen
  // for a feature-level run too, so that a scenario's `render:` typo is refused either way.
  auto world = cvslam::chooseRenderWorld(scenario, args.world);
  if (!world.ok()) return world.status();
  if (args.sensing != "images") return cvslam::SimulatedTeamRun::SensingFactory{};
  // The feature index needs a vocabulary of the detector's descriptor type (§6.6.3).
  auto vocabulary = cvslam::loadFeatureIndexVocabulary(config.frontend, config.effective.dir());
  if (!vocabulary.ok()) return vocabulary.status();
  return cvslam::makeRenderedSensingFactory(*world, config.frontend, *vocabulary);
}

/// Per-UAV counters for the closing summary.
struct AgentCounters {
  int frames = 0;
  double cpu_ms = 0.0;
  double first_loop_t = -1.0;
};

void printAgentSummary(const cvslam::SimulatedTeamRun& run, std::size_t i, const AgentCounters& c) {
  const cvslam::FilterStatistics& st = run.slam(i).statistics();
  const std::string loop =
      c.first_loop_t >= 0 ? "first at " + std::to_string(static_cast<int>(c.first_loop_t)) + " s"
                          : "none";
  std::printf(
      "  UAV%d: %d frames, %.2f ms/frame, map %zu landmarks, loop closure %s, gated out "
      "%ld of %ld observations, θ reductions %ld\n",
      run.agentId(i), c.frames, c.frames > 0 ? c.cpu_ms / c.frames : 0.0, run.slam(i).map().size(),
      loop.c_str(), st.observations_rejected, st.observations_accepted + st.observations_rejected,
      st.theta_reductions);
  const cvslam::InsPropagatorOptions& ins = run.slam(i).options().ins;
  if (ins.noise_monitor.enabled) {
    const cvslam::InsPropagator& model = run.slam(i).insModel();
    std::printf(
        "        IMU white noise assumed at the end (measured in flight, at least the "
        "configured): gyro %.3g rad/s/√Hz (%.1f× configured), accel %.3g m/s²/√Hz (%.1f×)\n",
        model.gyroNoiseDensity(), model.gyroNoiseDensity() / ins.gyro_noise_density,
        model.accelNoiseDensity(), model.accelNoiseDensity() / ins.accel_noise_density);
  }
  const auto* rs = dynamic_cast<const cvslam::RenderedSensing*>(&run.sensing(i));
  if (rs == nullptr) return;
  const cvslam::RenderedSensingStats& s = rs->stats();
  const double n = static_cast<double>(std::max(s.frames, 1L));
  std::printf(
      "        images: %.1f observations/frame; per frame: render %.1f ms, front end %.1f ms "
      "(detect %.1f, stereo %.1f, describe %.1f, index %.1f), association %.2f ms, filter "
      "%.2f ms; stereo precision %.4f (%ld checked), map "
      "association precision %.4f (%ld of %ld type-1 checked; %.4f of the %ld the filter "
      "used); disparity error of right matches mean %.3f px, RMS %.3f px; re-observed left "
      "pixel error RMS %.3f px; the filter assumed %.3f px\n",
      static_cast<double>(s.observations) / n, s.render_ms / n, s.front_end_ms / n,
      s.front_end.detect_ms / n, s.front_end.stereo_ms / n, s.front_end.describe_ms / n,
      s.front_end.index_ms / n, s.association_ms / n, s.filter_ms / n, s.stereoPrecision(),
      s.stereo_checked, s.associationPrecision(), s.associated_checked, s.associated,
      s.usedAssociationPrecision(), s.associated_checked - s.associated_unused_checked,
      s.disparityBias(), s.disparityRms(), s.reobservationRms(),
      run.slam(i).options().slam.pixel_sigma);
}

/// run.json: what, beyond every agent's config_used.yaml, the run needs to be repeated.
cvslam::RunInfo runInfo(const Args& args, const cvslam::sim::Scenario& scenario,
                        const cvslam::AgentConfig& config) {
  cvslam::RunInfo info;
  info.program = "cvslam_run";
  info.mode = args.mode;
  info.filter = config.filterName();
  info.map = config.mapName();
  info.scenario = args.scenario;
  info.seed = scenario.seed;
  info.duration_s = scenario.duration;
  info.sensing = args.sensing;
  info.world = args.world;
  info.pixel_noise = args.pixel_noise;
  info.linearised_at_truth = args.linearise_at_truth;
  for (const cvslam::sim::AgentSpec& a : scenario.agents) info.agents.push_back(a.id);
  info.config = config.effective.path();
  return info;
}

/// The ground station's options for --mode cc.
cvslam::Expected<cvslam::coop::CcTeamFilterOptions> groundStationOptions(
    const Args& args, const cvslam::AgentConfig& config) {
  if (!args.gs_config.empty()) return cvslam::coop::CcTeamFilterOptions::loadFile(args.gs_config);
  cvslam::coop::CcTeamFilterOptions o;
  // The joint filter keeps its own chart (docs/results/cc_vs_dc.md "Error chart").
  o.useAgentOptions(config.slam);
  o.association = args.sensing == "features" ? cvslam::coop::CcAssociation::kTrueIds
                                             : cvslam::coop::CcAssociation::kLocalIds;
  // With images, the agents' front-end overrides of the measurement model (local_ids applies
  // them).
  o.useAgentImageModel(config.frontend.resolve(config.slam.slam));
  return o;
}

/// Opens every agent's record (and writes its config_used.yaml) and the DC link.
Status openOutputs(const Args& args, const cvslam::SimulatedTeamRun& run,
                   const cvslam::AgentConfig& config,
                   std::map<int, cvslam::AgentRunRecorder>* recorders,
                   std::unique_ptr<cvslam::DcTeamLink>* dc) {
  std::map<int, cvslam::coop::DcCooperationOptions> coop;
  for (std::size_t i = 0; i < run.agentCount(); ++i) {
    const int id = run.agentId(i);
    // Each agent as its process: in the team's frame when its start is known, else in a frame
    // of its own, merged with its peers by place exchanges (docs/merge.md).
    coop[id] = config.coop;
    coop[id].frames_given = run.scenarioAgent(i).spec().start_known;
    if (Status s = (*recorders)[id].open(args.out, id, args.sensing == "images"); !s.ok()) return s;
    const std::string used = cvslam::agentDir(args.out, id) + "/config_used.yaml";
    if (Status s = config.effective.write(used); !s.ok()) return s;
  }
  if (args.mode != "dc") return Status::Ok();
  *dc = std::make_unique<cvslam::DcTeamLink>(coop, args.coop_loss);
  return (*dc)->open(args.out);
}

/// The true position of UAV `agent`'s landmarks: with images, where the renderer showed it was
/// initialised.
cvslam::simrun::CrossUavMatchAudit::Truth agentTruth(const cvslam::SimulatedTeamRun& run,
                                                     const std::map<int, std::size_t>& index_of,
                                                     int agent) {
  const cvslam::FrameSensing& s = run.sensing(index_of.at(agent));
  return [&s](int64_t landmark, Eigen::Vector3d* p) { return s.landmarkTruth(landmark, p); };
}

/// CC: the ground station's summary and, with images, its cross-UAV associations (local_ids)
/// against the truth.
void printGroundStationSummary(const cvslam::SimulatedTeamRun& run,
                               const std::map<int, std::size_t>& index_of,
                               const cvslam::CcTeamLink& cc,
                               const cvslam::simrun::CrossUavMatchAuditOptions& options,
                               const std::string& sensing, double duration_s) {
  cc.printSummary(stdout, duration_s);
  if (sensing != "images") return;
  cvslam::simrun::CrossUavMatchAudit audit(options);
  for (const cvslam::coop::CcCrossAssociation& c : cc.crossAssociations()) {
    if (index_of.count(c.agent) == 0 || index_of.count(c.mapper) == 0) continue;
    audit.fused(c.agent, c.local_id, agentTruth(run, index_of, c.agent), c.mapper,
                c.mapper_local_id, agentTruth(run, index_of, c.mapper));
  }
  const cvslam::simrun::CrossUavMatchReport& r = audit.report();
  std::printf(
      "  ground station cross-UAV associations against the truth: %ld, %ld right "
      "(precision %.1f %%), %ld without truth\n",
      r.fused, r.fused_right, 100.0 * r.precision(), r.fused_unknown);
}

/// Agent id -> its index in `run`.
std::map<int, std::size_t> agentIndices(const cvslam::SimulatedTeamRun& run) {
  std::map<int, std::size_t> index_of;
  for (std::size_t i = 0; i < run.agentCount(); ++i) index_of[run.agentId(i)] = i;
  return index_of;
}

/// How far auditMatches has read each agent's fused pairs and mapped points.
struct AuditProgress {
  std::map<int, std::size_t> fused, mapped;
};

/// DC: the frame of UAV `id` against every peer's state, and the pairs it fused since its last
/// frame, checked against the simulator's truth (simrun/cross_uav_match_audit.h).
void auditMatches(cvslam::SimulatedTeamRun& run, const std::map<int, std::size_t>& index_of,
                  const cvslam::DcTeamLink& dc, int id, int64_t t_us,
                  cvslam::simrun::CrossUavMatchAudit* audit, AuditProgress* progress) {
  // The points the cooperation mapped after this frame get their truth from this frame.
  const std::vector<cvslam::coop::MappedPoint>& mapped = dc.agent(id).mappedPoints();
  for (std::size_t i = progress->mapped[id]; i < mapped.size(); ++i)
    run.sensing(index_of.at(id)).nameLandmark(mapped[i].local_id, mapped[i].z);
  progress->mapped[id] = mapped.size();
  const auto truth = [&](int agent) { return agentTruth(run, index_of, agent); };
  const std::vector<cvslam::StateLandmark> own = run.slam(index_of.at(id)).stateLandmarks();
  for (const auto& [peer, k] : index_of) {
    if (peer != id)
      audit->observe(id, t_us, own, truth(id), peer, run.slam(k).stateLandmarks(), truth(peer));
  }
  const std::vector<cvslam::coop::FusedMatch>& fused = dc.agent(id).fusedMatches();
  for (std::size_t i = progress->fused[id]; i < fused.size(); ++i) {
    const cvslam::coop::FusedMatch& m = fused[i];
    const int64_t peer_id =
        index_of.count(m.peer) > 0 ? dc.agent(m.peer).sentLandmarkId(m.peer_seq, m.slot) : -1;
    audit->fused(id, m.local_id, truth(id), m.peer, peer_id, truth(m.peer), m.t_us);
  }
  progress->fused[id] = fused.size();
}

/// Writes every agent's map (landmarks.csv) and closes its record.
Status writeMaps(cvslam::SimulatedTeamRun& run,
                 std::map<int, cvslam::AgentRunRecorder>* recorders_in) {
  std::map<int, cvslam::AgentRunRecorder>& recorders = *recorders_in;
  // True landmark positions for the map's error columns: the true id (features) or the
  // surface the renderer showed where the landmark was initialised (images).
  for (std::size_t i = 0; i < run.agentCount(); ++i) {
    cvslam::AgentRunRecorder& recorder = recorders[run.agentId(i)];
    const cvslam::FrameSensing& agent_sensing = run.sensing(i);
    const cvslam::sim::ScenarioAgent& scenario_agent = run.scenarioAgent(i);
    Status s = recorder.writeMap(run.slam(i), [&](int64_t id, Eigen::Vector3d* p) {
      if (!agent_sensing.landmarkTruth(id, p)) return false;
      *p = scenario_agent.toOwnFrame(*p);  // the map is in the agent's own frame
      return true;
    });
    if (s.ok()) s = recorder.close();
    if (!s.ok()) return s;
  }
  return Status::Ok();
}

/// The ground station's joint filter holds every UAV in the team's frame: it needs every start
/// known (an agent that starts unknown estimates in a frame of its own, docs/merge.md).
Status checkStarts(const Args& args, const cvslam::sim::Scenario& scenario) {
  for (const cvslam::sim::AgentSpec& a : scenario.agents)
    if (!a.start_known && args.mode == "cc")
      return Status::Error("--mode cc needs every start known (agent " + std::to_string(a.id) +
                           " starts unknown); teams that start apart run --mode dc or single");
  return Status::Ok();
}

/// Estimated frames: the agent's state in its team frame once merged (trajectory_team.tum).
Status recordTeamState(const cvslam::DcTeamLink& dc, const cvslam::SimulatedFrame& f,
                       cvslam::AgentRunRecorder* recorder) {
  int root = 0;
  cvslam::Vector9d x_team;
  if (!dc.agent(f.agent_id).teamState(f.slam->vehicleState().head<9>(), &root, &x_team))
    return Status::Ok();
  return recorder->writer().addTeamState(static_cast<double>(f.t_us) * 1e-6, root, x_team);
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (auto exit_code = parseArgs(argc, argv, &args)) return *exit_code;
  auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
  if (!scenario.ok()) return fail(scenario.status().message());
  if (Status s = applyScenarioArgs(args, &*scenario); !s.ok()) return fail(s.message());
  auto config = cvslam::AgentConfig::load(args.config, CVSLAM_CONFIG_DIR "/agent.yaml",
                                          [](const cvslam::ConfigNode& root) {
                                            root.skip("agent");  // cvslam_agent's section
                                          });
  if (!config.ok()) return fail(config.status().message());
  config->coop.true_ids = args.sensing == "features";
  if (Status s = checkStarts(args, *scenario); !s.ok()) return fail(s.message());
  auto sensing = makeSensing(args, *scenario, *config);
  if (!sensing.ok()) return fail(sensing.status().message());
  auto team = cvslam::SimulatedTeamRun::create(*scenario, config->slam, *sensing);
  if (!team.ok()) return fail(team.status().message());
  cvslam::SimulatedTeamRun& run = **team;
  if (args.linearise_at_truth)
    if (Status s = run.lineariseAtTruth(); !s.ok()) return fail(s.message());

  std::map<int, cvslam::AgentRunRecorder> recorders;
  std::unique_ptr<cvslam::DcTeamLink> dc;
  if (Status s = openOutputs(args, run, *config, &recorders, &dc); !s.ok())
    return fail(s.message());
  std::unique_ptr<cvslam::CcTeamLink> cc;
  if (args.mode == "cc") {
    auto gs_options = groundStationOptions(args, *config);
    if (!gs_options.ok()) return fail(gs_options.status().message());
    cc = std::make_unique<cvslam::CcTeamLink>(*gs_options);
    if (Status s = cc->open(args.out, runInfo(args, *scenario, *config), run); !s.ok())
      return fail(s.message());
  }
  std::map<int, AgentCounters> counters;
  cvslam::simrun::CrossUavMatchAuditOptions audit_options;
  audit_options.max_descriptor_distance = config->coop.max_descriptor_distance;
  cvslam::simrun::CrossUavMatchAudit match_audit(audit_options);
  AuditProgress audited;
  const std::map<int, std::size_t> index_of = agentIndices(run);
  const double duration = scenario->duration;
  int next_progress = 10;
  const auto wall_start = std::chrono::steady_clock::now();
  Status run_status = run.run(
      [&](const cvslam::SimulatedFrame& f) -> Status {
        cvslam::AgentRunRecorder& recorder = recorders[f.agent_id];
        if (dc) {
          if (Status s = dc->afterFrame(f.agent_id, f.sensing->lastObservations(), *f.mutable_slam,
                                        &recorder.writer());
              !s.ok())
            return s;
          auditMatches(run, index_of, *dc, f.agent_id, f.t_us, &match_audit, &audited);
          if (Status s = recordTeamState(*dc, f, &recorder); !s.ok()) return s;
        }
        const double t = static_cast<double>(f.t_us) * 1e-6;
        AgentCounters& c = counters[f.agent_id];
        c.cpu_ms += f.time_ms;
        ++c.frames;
        if (f.report->loop_closure && c.first_loop_t < 0) c.first_loop_t = t;
        const cvslam::Vector9d truth = f.truth->eulerLayout();
        if (f.truth->biases_known) {  // a recorded IMU's stay NaN in biases.csv (no bias NEES)
          cvslam::Vector6d bias_truth;
          bias_truth << f.truth->accel_bias, f.truth->gyro_bias;
          recorder.setBiasTruth(bias_truth);
        }
        if (cc) {
          if (Status s = cc->afterFrame(f.agent_id, *f.pipeline, &truth, &recorder); !s.ok())
            return s;
        } else if (Status s = recorder.addFrame(*f.pipeline, &truth); !s.ok()) {
          return s;
        }
        if (!args.quiet && t >= duration * next_progress / 100.0) {
          std::fprintf(stderr, "cvslam_run: %3d%%  t = %.0f s\n", next_progress, t);
          next_progress += 10;
        }
        return Status::Ok();
      },
      [&](int id, const cvslam::ImuSample& sample) {
        if (cc) cc->addImu(id, sample);
      });
  if (!run_status.ok()) return fail(run_status.message());
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  if (Status s = writeMaps(run, &recorders); !s.ok()) return fail(s.message());
  if (cc) {
    // The joint map's ids are the true ids with features; with images they are the ground
    // station's own (no truth).
    const cvslam::FrameSensing& first = run.sensing(0);
    cvslam::coop::GroundStationRecorder::LandmarkTruth truth;
    if (args.sensing == "features")
      truth = [&](int64_t id, Eigen::Vector3d* p) { return first.landmarkTruth(id, p); };
    if (Status s = cc->close(truth); !s.ok()) return fail(s.message());
  }
  if (dc) {
    if (Status s = cvslam::writeJsonFile(args.out + "/cross_uav_matches.json", match_audit.json());
        !s.ok())
      return fail(s.message());
  }
  cvslam::RunInfo info = runInfo(args, *scenario, *config);
  for (std::size_t i = 0; i < run.agentCount(); ++i)
    if (!run.scenarioAgent(i).spec().start_known)
      info.frames_in_world[run.agentId(i)] = run.scenarioAgent(i).ownFrameInWorld();
  if (Status s = cvslam::writeRunInfo(args.out, info); !s.ok()) return fail(s.message());

  std::printf("cvslam_run: %s, %s, map %s, %.0f s simulated in %.1f s wall (%.1fx real time)\n",
              scenario->name.c_str(), info.filter.c_str(), info.map.c_str(), duration, wall_s,
              duration / std::max(wall_s, 1e-9));
  for (std::size_t i = 0; i < run.agentCount(); ++i)
    printAgentSummary(run, i, counters[run.agentId(i)]);
  if (dc) {
    dc->printSummary(stdout, duration);
    std::printf("  %s\n", match_audit.summaryLine().c_str());
  }
  if (cc) printGroundStationSummary(run, index_of, *cc, audit_options, args.sensing, duration);
  std::printf("  outputs in %s (evaluate with: cvslam_eval --run %s --summary-json F)\n",
              args.out.c_str(), args.out.c_str());
  return 0;
}
