// One step of the ground station's joint filter (coop/cc_team_filter.h; target:
// median ≤ 10 ms, p95 ≤ 25 ms for 5 UAVs at k = 20): config/scenarios/team5.yaml with
// feature-level sensing. The first kWarmUpS seconds fill the joint state (5 vehicle blocks of
// 15, each UAV's 20 nearest landmarks + new ones, a growing archive); each benchmark iteration
// is then the next batch in time order (propagation over its IMU samples, map management,
// updates, initialisation), timed alone. Counters: median and p95 of the steps, state size.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "cvslam/coop/cc_batch_builder.h"
#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"

namespace cvslam {
namespace {

constexpr double kWarmUpS = 20.0;  // joint filter filled before timing [s]
constexpr double kTimedS = 10.0;   // batches timed after it [s]

struct Recorded {
  std::unique_ptr<coop::CcTeamFilter> filter;     // after the warm-up
  std::vector<coop::CcObservationBatch> batches;  // the timed ones, in order
};

/// Runs team5 for kWarmUpS + kTimedS: the joint filter processes the warm-up batches, the
/// rest are kept for timing.
Recorded record() {
  Recorded out;
  auto sc =
      sim::Scenario::loadFile(std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/team5.yaml");
  if (!sc.ok()) return out;
  sc->duration = kWarmUpS + kTimedS;
  coop::CcTeamFilterOptions o;
  o.slam.map.k = 20;
  auto run = SimulatedTeamRun::create(*sc, o.slam);
  if (!run.ok()) return out;
  out.filter = std::make_unique<coop::CcTeamFilter>(o);
  std::map<int, coop::CcBatchBuilder> builders;
  for (std::size_t i = 0; i < (*run)->agentCount(); ++i) {
    const AgentFilterSetup& s = (*run)->setup(i);
    const int id = (*run)->agentId(i);
    (void)out.filter->addVehicle(id, (*run)->slam(i).camera(), s.t0_us, s.x0, s.P0, &s.options.ins);
    builders.emplace(id, coop::CcBatchBuilder(id));
  }
  const auto warm_up_us = static_cast<int64_t>(kWarmUpS * 1e6);
  (void)(*run)->run(
      [&](const SimulatedFrame& f) -> Status {
        coop::CcObservationBatch b = builders.at(f.agent_id).takeBatch(f.pipeline->lastFrame());
        if (f.t_us < warm_up_us) return out.filter->processBatch(b);
        out.batches.push_back(std::move(b));
        return Status::Ok();
      },
      [&](int id, const ImuSample& s) { builders.at(id).addImu(s); });
  return out;
}

void BM_CcTeamFilterStep5Uavs(benchmark::State& st) {
  Recorded r = record();
  if (!r.filter || r.batches.empty()) {
    st.SkipWithError("team5 could not be simulated");
    return;
  }
  std::vector<double> ms;
  std::size_t next = 0;
  int state_size = 0;
  for (auto _ : st) {
    if (next == r.batches.size()) {
      st.SkipWithError("more iterations than recorded batches");
      break;
    }
    coop::CcStepReport report;
    const auto t0 = std::chrono::steady_clock::now();
    const Status s = r.filter->processBatch(r.batches[next++], &report);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    st.SetIterationTime(dt);
    benchmark::DoNotOptimize(s.ok());
    ms.push_back(dt * 1e3);
    state_size = std::max(state_size, report.state_size);
  }
  std::sort(ms.begin(), ms.end());
  if (ms.empty()) return;
  st.counters["median_ms"] = ms[ms.size() / 2];
  st.counters["p95_ms"] = ms[static_cast<std::size_t>(0.95 * static_cast<double>(ms.size() - 1))];
  st.counters["max_state"] = state_size;
  st.counters["vehicles"] = static_cast<double>(r.filter->vehicles().size());
}
// 5 UAVs at 10 Hz over kTimedS: 500 batches, each timed once.
BENCHMARK(BM_CcTeamFilterStep5Uavs)
    ->UseManualTime()
    ->Iterations(500)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cvslam

BENCHMARK_MAIN();
