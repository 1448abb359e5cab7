// What finding the frames between agents costs per frame (docs/merge.md): a shipped team flown
// at the feature level with every start unknown (the place descriptors, the requests and
// answers of place exchanges, the geometric verifications, the relation book — and, once a
// relation is adopted, the exchanges across frames) against the same team with the starts
// known (the DC exchange alone). Each agent's DcCooperation::afterFrame, where all of it runs,
// is timed; messages go straight to the peers' on*() as in cvslam_run (without the encoding).
//
//   build/tests/bench_place_recognition [--benchmark_filter=...]
//
// Counters: coop_ms_per_frame (mean over every agent's frames), coop_ms_max (the slowest
// frame), verifications and frames (per run, all agents).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "cvslam/coop/agent_config.h"
#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"

namespace cvslam {
namespace {

struct TeamCost {
  double coop_ms = 0.0, coop_ms_max = 0.0;
  int64_t frames = 0, verifications = 0;
  bool ok = false;
};

TeamCost flyTeam(const std::string& scenario_name, bool starts_known, double duration_s) {
  TeamCost cost;
  auto config = AgentConfig::load({}, CVSLAM_SOURCE_DIR "/config/agent.yaml",
                                  [](const ConfigNode& root) { root.skip("agent"); });
  auto scenario =
      sim::Scenario::loadFile(CVSLAM_SOURCE_DIR "/config/scenarios/" + scenario_name + ".yaml");
  if (!config.ok() || !scenario.ok()) {
    std::fprintf(stderr, "%s\n",
                 (!config.ok() ? config.status() : scenario.status()).message().c_str());
    return cost;
  }
  if (Status st = scenario->overrideStarts(starts_known); !st.ok()) {
    std::fprintf(stderr, "%s\n", st.message().c_str());
    return cost;
  }
  scenario->duration = std::min(scenario->duration, duration_s);
  auto run = SimulatedTeamRun::create(*scenario, config->slam);
  if (!run.ok()) {
    std::fprintf(stderr, "%s\n", run.status().message().c_str());
    return cost;
  }
  std::map<int, std::unique_ptr<coop::DcCooperation>> agents;
  for (const sim::AgentSpec& a : scenario->agents) {
    coop::DcCooperationOptions o = config->coop;
    o.true_ids = true;
    o.frames_given = starts_known;
    agents[a.id] = std::make_unique<coop::DcCooperation>(a.id, o, 1000 + a.id);
  }
  const Status s = (*run)->run([&](const SimulatedFrame& f) {
    coop::CoopOutbox box;
    const auto t0 = std::chrono::steady_clock::now();
    if (Status st =
            agents.at(f.agent_id)->afterFrame(f.sensing->lastObservations(), *f.mutable_slam, &box);
        !st.ok())
      return st;
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    cost.coop_ms += ms;
    cost.coop_ms_max = std::max(cost.coop_ms_max, ms);
    ++cost.frames;
    for (auto& [id, peer] : agents) {
      if (id == f.agent_id) continue;
      if (box.summary) peer->onSummary(*box.summary);
      if (box.index) peer->onIndex(*box.index);
      for (const auto& r : box.requests)
        if (r.to_agent == id) peer->onRequest(r);
      for (const auto& l : box.shared)
        if (l.to_agent == id) peer->onShared(l);
    }
    return Status::Ok();
  });
  for (const auto& [id, a] : agents) cost.verifications += a->statistics().verifications;
  cost.ok = s.ok();
  return cost;
}

// Args: scenario (0 team3_aerial, 1 team5), starts (0 known, 1 unknown).
void placeRecognitionPerFrame(benchmark::State& state) {
  const std::string scenario = state.range(0) == 0 ? "team3_aerial" : "team5";
  const bool known = state.range(1) == 0;
  TeamCost total;
  int runs = 0;
  for (auto _ : state) {
    const TeamCost c = flyTeam(scenario, known, 60.0);
    if (!c.ok) {
      state.SkipWithError("the team could not be flown");
      return;
    }
    total.coop_ms += c.coop_ms;
    total.coop_ms_max = std::max(total.coop_ms_max, c.coop_ms_max);
    total.frames += c.frames;
    total.verifications += c.verifications;
    ++runs;
  }
  state.SetLabel(scenario + (known ? ", starts known" : ", starts unknown"));
  const double frames = static_cast<double>(total.frames);
  state.counters["coop_ms_per_frame"] = total.coop_ms / frames;
  state.counters["coop_ms_max"] = total.coop_ms_max;
  state.counters["frames"] = frames / runs;
  state.counters["verifications"] = static_cast<double>(total.verifications) / runs;
}
BENCHMARK(placeRecognitionPerFrame)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cvslam

BENCHMARK_MAIN();
