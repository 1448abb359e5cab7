// The CC-VSLAM joint filter (coop/cc_team_filter.h): one vehicle is VisualInertialSlam exactly;
// two UAVs on known initial poses (§6.3.1) beat their single filters; a type-2 observation
// moves the UAV that mapped the landmark; the state stays bounded by k-nearest management;
// each UAV's vehicle NEES is inside its χ² band; bad batches are counted, not fatal.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "coop_team_fixture.h"
#include "cvslam/coop/cc_batch_builder.h"
#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/io/config_node.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "nees_band.h"

namespace cvslam {
namespace {

/// Two UAVs on one 25 m circle, UAV2 10° behind over the same ground; both start at known
/// poses (thesis §6.3.1: initial estimate = truth with the configured 1σ).
std::string knownPosePair(double duration, uint64_t seed) {
  return cooptest::twoUavScenario(duration, seed, false);
}

/// Per UAV: RMS position error of its own filter (single mode) and of the ground station's
/// estimate, and the mean 9-dof NEES of the latter.
struct PerUav {
  double single_sq = 0.0, cc_sq = 0.0, nees = 0.0;
  int frames = 0;
  double singleRms() const { return std::sqrt(single_sq / frames); }
  double ccRms() const { return std::sqrt(cc_sq / frames); }
  double neesMean() const { return nees / frames; }
};

struct CcRun {
  std::map<int, PerUav> uav;
  coop::CcTeamStatistics stats;
  int max_state_size = 0;
  bool ok = false;
};

/// Called after each processed batch: the filter, the report, and UAV1's estimate before it.
using StepCheck = std::function<void(const coop::CcTeamFilter&, const coop::CcStepReport&,
                                     const VehicleEstimate& uav1_before)>;

/// Runs `scenario` with every agent's own filter and the joint filter beside them, as
/// cvslam_run --mode cc does (tools/cc_team_link.cpp).
CcRun runCc(const std::string& scenario, const coop::CcTeamFilterOptions& options,
            const StepCheck& check = {}) {
  CcRun out;
  auto sc = sim::Scenario::fromString(scenario, "cc_test.yaml");
  EXPECT_TRUE(sc.ok()) << sc.status().message();
  if (!sc.ok()) return out;
  auto run = SimulatedTeamRun::create(*sc, options.slam);
  EXPECT_TRUE(run.ok()) << run.status().message();
  if (!run.ok()) return out;
  coop::CcTeamFilter gs(options);
  std::map<int, coop::CcBatchBuilder> builders;
  for (std::size_t i = 0; i < (*run)->agentCount(); ++i) {
    const AgentFilterSetup& setup = (*run)->setup(i);
    const int id = (*run)->agentId(i);
    EXPECT_TRUE(gs.addVehicle(id, (*run)->slam(i).camera(), setup.t0_us, setup.x0, setup.P0,
                              &setup.options.ins)
                    .ok());
    builders.emplace(id, coop::CcBatchBuilder(id));
  }
  const Status s = (*run)->run(
      [&](const SimulatedFrame& f) -> Status {
        const VehicleEstimate before = *gs.estimate(1);
        coop::CcStepReport report;
        const coop::CcObservationBatch batch =
            builders.at(f.agent_id).takeBatch(f.pipeline->lastFrame());
        if (Status st = gs.processBatch(batch, &report); !st.ok()) return st;
        if (check) check(gs, report, before);
        out.max_state_size = std::max(out.max_state_size, report.state_size);
        const VehicleEstimate e = *gs.estimate(f.agent_id);
        Eigen::Matrix<double, 9, 1> err;
        err << e.x_v.head<3>() - f.truth->p_BinN, e.x_v.segment<3>(3) - f.truth->v_B,
            e.x_v.segment<3>(6) - f.truth->euler;
        for (int k = 6; k < 9; ++k) err(k) = wrapAngle(err(k));
        PerUav& u = out.uav[f.agent_id];
        u.cc_sq += err.head<3>().squaredNorm();
        u.single_sq += (f.slam->vehicleState().head<3>() - f.truth->p_BinN).squaredNorm();
        u.nees += err.dot(e.P_v.topLeftCorner<9, 9>().ldlt().solve(err));
        ++u.frames;
        return Status::Ok();
      },
      [&](int id, const ImuSample& sample) { builders.at(id).addImu(sample); });
  EXPECT_TRUE(s.ok()) << s.message();
  out.stats = gs.statistics();
  out.ok = s.ok();
  return out;
}

coop::CcTeamFilterOptions defaultOptions() {
  return coop::CcTeamFilterOptions{};
}

/// The ground station's configuration (config/ground_station.yaml: bias states, FEJ, OC).
coop::CcTeamFilterOptions projectOptions() {
  coop::CcTeamFilterOptions o;
  auto root = ConfigNode::loadFile(std::string(CVSLAM_SOURCE_DIR) + "/config/ground_station.yaml");
  EXPECT_TRUE(root.ok());
  if (root.ok()) {
    EXPECT_TRUE(o.slam.load(*root).ok());
  }
  return o;
}

TEST(CcTeamFilter, OneVehicleIsVisualInertialSlamExactly) {
  // The joint filter calls the same models in the same order: with one UAV its estimate is
  // the UAV's own filter's, bit for bit, at every frame (re-activation as VisualInertialSlam's).
  auto sc = sim::Scenario::fromString(knownPosePair(6.0, 3), "cc_test.yaml");
  ASSERT_TRUE(sc.ok());
  sc->agents.resize(1);
  coop::CcTeamFilterOptions o = defaultOptions();
  auto run = SimulatedTeamRun::create(*sc, o.slam);  // the joint filter's estimator choices
  ASSERT_TRUE(run.ok());
  o.reactivation_inflation = 0.0;
  coop::CcTeamFilter gs(o);
  const AgentFilterSetup& setup = (*run)->setup(0);
  ASSERT_TRUE(gs.addVehicle(1, (*run)->slam(0).camera(), setup.t0_us, setup.x0, setup.P0,
                            &setup.options.ins)
                  .ok());
  coop::CcBatchBuilder builder(1);
  int frames = 0;
  ASSERT_TRUE((*run)
                  ->run(
                      [&](const SimulatedFrame& f) -> Status {
                        if (Status s = gs.processBatch(builder.takeBatch(f.pipeline->lastFrame()));
                            !s.ok())
                          return s;
                        const VehicleEstimate e = *gs.estimate(1);
                        EXPECT_EQ(e.t_us, f.t_us);
                        EXPECT_EQ(e.x_v, f.slam->vehicleState()) << "t=" << f.t_us;
                        EXPECT_EQ(e.P_v, f.slam->vehicleCovariance()) << "t=" << f.t_us;
                        ++frames;
                        return Status::Ok();
                      },
                      [&](int, const ImuSample& s) { builder.addImu(s); })
                  .ok());
  EXPECT_GT(frames, 50);
  EXPECT_EQ(gs.map().size(), (*run)->slam(0).map().size());
}

TEST(CcTeamFilter, TwoUavsOnKnownPosesBeatTheirSingleFilters) {
  // §6.6.7: the joint filter uses every UAV's observations of the shared ground. Over three
  // seeds, each UAV's seed-mean position RMS must be at least 15 % below its single filter's.
  std::map<int, double> single, cc;
  for (uint64_t seed : {1u, 2u, 3u}) {
    const CcRun r = runCc(knownPosePair(12.0, seed), projectOptions());
    ASSERT_TRUE(r.ok);
    for (const auto& [id, u] : r.uav) {
      single[id] += u.singleRms() / 3.0;
      cc[id] += u.ccRms() / 3.0;
    }
    EXPECT_GT(r.stats.agents.at(2).type2, 20) << "UAV2 must re-observe UAV1's landmarks";
  }
  for (const auto& [id, s] : single) {
    EXPECT_LT(cc[id], 0.85 * s) << "UAV" << id << ": CC " << cc[id] << " m, single " << s << " m";
  }
}

TEST(CcTeamFilter, TypeTwoObservationMovesTheVehicleThatMappedTheLandmark) {
  // A landmark of UAV1 re-observed by UAV2 updates UAV1 through the cross-covariance of the
  // shared map: UAV1's estimate changes in UAV2's step, and its covariance does not grow.
  int moved = 0, type2_steps = 0;
  const CcRun r = runCc(knownPosePair(4.0, 5), defaultOptions(),
                        [&](const coop::CcTeamFilter& gs, const coop::CcStepReport& rep,
                            const VehicleEstimate& before) {
                          if (rep.agent_id != 2 || rep.type2 == 0) return;
                          ++type2_steps;
                          const VehicleEstimate after = *gs.estimate(1);
                          EXPECT_EQ(after.t_us, before.t_us);  // UAV1 is not propagated
                          if ((after.x_v - before.x_v).norm() > 1e-9) ++moved;
                          EXPECT_LE(after.P_v.trace(), before.P_v.trace() + 1e-12);
                        });
  ASSERT_TRUE(r.ok);
  ASSERT_GT(type2_steps, 5);
  EXPECT_EQ(moved, type2_steps);
}

TEST(CcTeamFilter, KNearestKeepsTheJointStateBounded) {
  // Each UAV keeps its k nearest active (plus the landmarks new in its step), the team at most
  // `held` held landmarks: the state is at most M·(vehicle + 3(k + max_new)) + 3·held however
  // long the flight and however large the joint map.
  coop::CcTeamFilterOptions o = defaultOptions();
  o.slam.map.k = 6;
  const int max_new = o.slam.slam.max_new_landmarks_per_frame;
  const int held = o.slam.slam.held_landmarks;
  const int vehicle = InsPropagator(o.slam.ins).stateSize();
  std::size_t map_size = 0;
  const CcRun r = runCc(
      knownPosePair(20.0, 2), o,
      [&](const coop::CcTeamFilter& gs, const coop::CcStepReport& rep, const VehicleEstimate&) {
        for (int id : gs.vehicles())
          EXPECT_LE(static_cast<int>(gs.activeLandmarks(id).size()), o.slam.map.k + max_new);
        EXPECT_LE(rep.state_size, 2 * (vehicle + 3 * (o.slam.map.k + max_new)) + 3 * held);
        map_size = gs.map().size();
      });
  ASSERT_TRUE(r.ok);
  EXPECT_LE(r.max_state_size, 2 * (vehicle + 3 * (o.slam.map.k + max_new)) + 3 * held);
  EXPECT_GT(map_size, static_cast<std::size_t>(r.max_state_size / 3)) << "most are archived";
}

TEST(CcTeamFilter, EachUavsVehicleNeesIsInsideTheBandFromPerturbedStarts) {
  // Consistency of the joint estimate: each UAV's mean 9-dof NEES over seeds 4–9, its estimate
  // started from a draw of its uncertainty (the scenarios' default, 0.1 m / 1°), inside the χ²
  // band of 6 runs (tests/core/nees_band.h: [5.93, 12.70]; measured 9.19 and 8.69). The ground
  // station's configuration (config/ground_station.yaml); from exact starts the same runs are
  // below the band (2.4–5.3: errors start at zero, their covariance does not).
  const std::vector<uint64_t> seeds = {4, 5, 6, 7, 8, 9};
  std::map<int, double> nees;
  for (uint64_t seed : seeds) {
    const CcRun r = runCc(cooptest::twoUavScenario(12.0, seed, false), projectOptions());
    ASSERT_TRUE(r.ok);
    for (const auto& [id, u] : r.uav) nees[id] += u.neesMean() / static_cast<double>(seeds.size());
  }
  const test::NeesBand band = test::neesBand(9, static_cast<int>(seeds.size()));
  ASSERT_EQ(nees.size(), 2u);
  for (const auto& [id, v] : nees) {
    RecordProperty("nees_uav" + std::to_string(id), std::to_string(v));
    EXPECT_TRUE(band.contains(v)) << "UAV" << id << ": mean NEES " << v << ", band " << band.str();
  }
}

TEST(CcTeamFilter, TwoUavsThatDriftedAlikeMeetThroughTheIteratedUpdate) {
  // Both UAVs start 1.5 m uncertain (perturbed) over the same ground: a rendezvous for each
  // whatever the other's uncertainty (cc.rendezvous_sigma_ratio 0, the default) against the
  // gated per-observation updates of ratio 3 (the default before; thesis_loop seeds 31–46:
  // CC worse than DC). Seeds 11–16, no default chosen on them. Without the second-order term
  // (as the rendezvous was measured) the team's summed position RMS must drop by 5 % and its
  // summed 9-dof NEES by 40 % (measured: 15.57 vs 18.54 m, 112 vs 266). With the term (the
  // shipped configuration) the rendezvous team must stay within 1.5×
  // its 12 × 9 degrees of freedom and within 2 % of that error (measured: 107, 15.61 m; the
  // gated updates then come as close: 106, 15.62 m; docs/ground_station.md).
  const std::string lost =
      "    initial_uncertainty: {position_sigma: [1.5, 1.5, 0.5], perturb: true}\n";
  constexpr int kRuns = 3;  // ratio 0, ratio 3 (both without the term), ratio 0 shipped
  double rms[kRuns] = {0.0, 0.0, 0.0}, nees[kRuns] = {0.0, 0.0, 0.0};
  ASSERT_TRUE(projectOptions().slam.slam.second_order_noise);  // run 2 is the shipped one
  for (uint64_t seed = 11; seed <= 16; ++seed) {
    std::string sc = cooptest::twoUavScenario(12.0, seed);
    sc.insert(sc.find("    camera_rate_hz"), lost);  // UAV1 as lost as UAV2
    for (int k = 0; k < kRuns; ++k) {
      coop::CcTeamFilterOptions o = projectOptions();
      o.rendezvous_sigma_ratio = k == 1 ? 3.0 : 0.0;
      o.slam.slam.second_order_noise = k == 2;
      const CcRun r = runCc(sc, o);
      ASSERT_TRUE(r.ok);
      for (const auto& [id, u] : r.uav) {
        rms[k] += u.ccRms();
        nees[k] += u.neesMean();
      }
    }
  }
  RecordProperty("rms_sum_ratio0", std::to_string(rms[0]));
  RecordProperty("rms_sum_ratio3", std::to_string(rms[1]));
  RecordProperty("rms_sum_shipped", std::to_string(rms[2]));
  RecordProperty("nees_sum_ratio0", std::to_string(nees[0]));
  RecordProperty("nees_sum_ratio3", std::to_string(nees[1]));
  RecordProperty("nees_sum_shipped", std::to_string(nees[2]));
  EXPECT_LT(rms[0], 0.95 * rms[1]) << "Σ RMS " << rms[0] << " vs " << rms[1] << " m";
  EXPECT_LT(nees[0], 0.6 * nees[1]) << "Σ NEES " << nees[0] << " vs " << nees[1];
  EXPECT_LT(nees[2], 1.5 * 9.0 * 12.0) << "Σ NEES shipped " << nees[2];
  EXPECT_LT(rms[2], 1.02 * rms[0]) << "Σ RMS shipped " << rms[2] << " vs " << rms[0] << " m";
}

TEST(CcTeamFilter, AUavMeetingAnotherMapThroughHeldLandmarksMeetsByTheIteratedUpdate) {
  // UAV2, lost (1σ 1.5 m, perturbed) and 1.5 s behind UAV1 over the same ground, with k = 2: by
  // the time it sees UAV1's landmarks most have left UAV1's k nearest and are held, and a held
  // landmark comes back exactly in step 3, after step 2 looked for meetings. Such a first
  // meeting must still be a rendezvous (thesis_loop seed 2: one held landmark 5 m off, taken by
  // the plain EKF update, moved the UAVs 5.2 and 3.5 m and left both 2 m off at σ 1.4 m).
  // Seeds 11–16, no default chosen on them.
  double nees = 0.0;
  for (uint64_t seed = 11; seed <= 16; ++seed) {
    coop::CcTeamFilterOptions o = projectOptions();
    o.slam.map.k = 2;
    const CcRun r = runCc(cooptest::twoUavScenario(12.0, seed), o);
    ASSERT_TRUE(r.ok);
    EXPECT_EQ(r.stats.agents.at(2).rendezvous, 1) << "seed " << seed;
    for (const auto& [id, u] : r.uav) nees += u.neesMean();
  }
  // ... and consistently: the 12 runs' mean 9-dof NEES inside their χ² band ([6.76, 11.55];
  // measured 8.30).
  const test::NeesBand band = test::neesBand(9, 12);
  RecordProperty("nees_mean", std::to_string(nees / 12.0));
  EXPECT_TRUE(band.contains(nees / 12.0)) << "mean NEES " << nees / 12.0 << ", band " << band.str();
}

/// A filter with UAV1 at rest at the origin, for the bad-input tests.
coop::CcTeamFilter oneRestingVehicle() {
  coop::CcTeamFilter gs(defaultOptions());
  const int n = InsPropagator(defaultOptions().slam.ins).stateSize();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd P = Eigen::MatrixXd::Identity(n, n) * 0.01;
  EXPECT_TRUE(gs.addVehicle(1, StereoCamera(StereoCameraOptions{}), 0, x, P).ok());
  return gs;
}

coop::CcObservationBatch restBatch(int agent, int64_t t_us) {
  coop::CcObservationBatch b;
  b.agent_id = agent;
  b.t_us = b.frame.t_us = t_us;
  for (int64_t t = t_us - 50000; t <= t_us; t += 5000) {
    if (t <= 0) continue;
    ImuSample s;
    s.t_us = t;
    s.accel_B = Eigen::Vector3d(0, 0, -9.81);
    b.imu.push_back(s);
  }
  StereoObservation obs;
  obs.z = Eigen::Vector4d(400, 300, 380, 300);
  obs.landmark_id = obs.index = 7;
  b.frame.observations.push_back(obs);
  return b;
}

TEST(CcTeamFilter, ImageLandmarkIdsUnderTrueIdAssociationAreRefusedWithWhatToDo) {
  // An image agent's batch (local landmark ids, visual-word indices) at a ground station left
  // at true_ids would join unrelated landmarks of different UAVs: refused, counted, explained.
  coop::CcTeamFilter gs = oneRestingVehicle();
  ASSERT_EQ(gs.options().association, coop::CcAssociation::kTrueIds);
  ASSERT_TRUE(gs.processBatch(restBatch(1, 100000)).ok());  // feature level: id = index
  const VehicleEstimate before = *gs.estimate(1);
  coop::CcObservationBatch images = restBatch(1, 200000);
  images.frame.observations[0].landmark_id = 3;  // the agent's own id; index 7: its word
  coop::CcStepReport report;
  const Status s = gs.processBatch(images, &report);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("local_ids"), std::string::npos) << s.message();
  EXPECT_EQ(gs.statistics().agents.at(1).refused.at("invalid_local_ids"), 1);
  EXPECT_EQ(gs.estimate(1)->x_v, before.x_v);
  // Unnamed observations (landmark id −1) are not evidence either way.
  coop::CcObservationBatch unnamed = restBatch(1, 200000);
  unnamed.frame.observations[0].landmark_id = -1;
  EXPECT_TRUE(gs.processBatch(unnamed).ok());
}

TEST(CcTeamFilter, BadBatchesAreCountedAndChangeNothing) {
  coop::CcTeamFilter gs = oneRestingVehicle();
  ASSERT_TRUE(gs.processBatch(restBatch(1, 100000)).ok());
  const VehicleEstimate before = *gs.estimate(1);
  const int64_t version = gs.mapVersion();
  coop::CcStepReport report;

  EXPECT_FALSE(gs.processBatch(restBatch(9, 200000), &report).ok());  // unknown agent
  EXPECT_FALSE(report.accepted);
  coop::CcObservationBatch nan_pixel = restBatch(1, 200000);
  nan_pixel.frame.observations[0].z(1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(gs.processBatch(nan_pixel, &report).ok());
  coop::CcObservationBatch nan_imu = restBatch(1, 200000);
  nan_imu.imu[2].gyro_B(0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(gs.processBatch(nan_imu, &report).ok());
  coop::CcObservationBatch absurd = restBatch(1, 200000);
  absurd.frame.observations[0].z(0) = 1e12;
  EXPECT_FALSE(gs.processBatch(absurd, &report).ok());
  coop::CcObservationBatch late_imu = restBatch(1, 200000);
  late_imu.imu.back().t_us = 300000;  // after the frame
  EXPECT_FALSE(gs.processBatch(late_imu, &report).ok());
  coop::CcObservationBatch mismatched = restBatch(1, 200000);
  mismatched.frame.t_us = 150000;
  EXPECT_FALSE(gs.processBatch(mismatched, &report).ok());
  EXPECT_FALSE(gs.processBatch(restBatch(1, 100000), &report).ok());  // stale: repeated
  EXPECT_FALSE(gs.processBatch(restBatch(1, 50000), &report).ok());   // stale: older
  EXPECT_EQ(report.reason, "not after the vehicle's last batch");

  const coop::CcTeamStatistics& st = gs.statistics();
  EXPECT_EQ(st.rejected_unknown_agent, 1);
  EXPECT_EQ(st.rejected_invalid, 5);
  EXPECT_EQ(st.rejected_stale, 2);
  EXPECT_EQ(st.batches, 1);
  EXPECT_EQ(st.agents.at(1).rejected, 7);
  // Each refusal under its own reason, per UAV.
  const std::map<std::string, long> expected = {{"invalid_pixels", 2},
                                                {"invalid_imu_not_finite", 1},
                                                {"invalid_imu_after_frame", 1},
                                                {"invalid_frame_time", 1},
                                                {"stale", 2}};
  EXPECT_EQ(st.agents.at(1).refused, expected);
  EXPECT_NE(st.refusalSummary().find("UAV1 "), std::string::npos);
  EXPECT_EQ(coop::refusalsOf("gs: batches 1, refused 7: " + st.refusalSummary(), 1),
            "invalid_frame_time 1, invalid_imu_after_frame 1, invalid_imu_not_finite 1, "
            "invalid_pixels 2, stale 2");
  EXPECT_EQ(coop::refusalsOf("gs: refused 7: " + st.refusalSummary(), 2), "");
  const VehicleEstimate after = *gs.estimate(1);
  EXPECT_EQ(after.x_v, before.x_v);
  EXPECT_EQ(after.P_v, before.P_v);
  EXPECT_EQ(gs.mapVersion(), version);
  // The filter goes on with the next good batch.
  EXPECT_TRUE(gs.processBatch(restBatch(1, 200000)).ok());
}

TEST(CcTeamFilter, ANoisyNegativeDisparityIsAMeasurementNotAnInvalidBatch) {
  // A distant landmark's pair with the simulator's pixel noise: the agent's filter updates
  // with it, so the ground station must take the batch (it refused every such batch).
  coop::CcTeamFilter gs = oneRestingVehicle();
  ASSERT_TRUE(gs.processBatch(restBatch(1, 100000)).ok());
  coop::CcObservationBatch far = restBatch(1, 150000);
  StereoObservation obs = far.frame.observations[0];
  obs.z = Eigen::Vector4d(500, 300, 500.4, 300);  // disparity −0.4 px
  obs.landmark_id = obs.index = 8;
  far.frame.observations.push_back(obs);
  coop::CcStepReport report;
  EXPECT_TRUE(gs.processBatch(far, &report).ok()) << report.reason;
  EXPECT_EQ(gs.statistics().rejected(), 0);
}

TEST(CcTeamFilter, ABatchLostOnTheWayIsBridgedALongGapRefusesOnlyItsOwnBatch) {
  coop::CcTeamFilter gs = oneRestingVehicle();
  ASSERT_TRUE(gs.processBatch(restBatch(1, 100000)).ok());
  // The batches at 150 and 200 ms never arrive: their IMU samples are missing, a 110 ms gap
  // longer than ins.max_dt (the ground station then refused every later batch of that UAV).
  const coop::CcTeamFilterOptions defaults;
  ASSERT_LT(defaults.slam.ins.max_dt, 0.11);
  coop::CcStepReport report;
  ASSERT_TRUE(gs.processBatch(restBatch(1, 260000), &report).ok()) << report.reason;
  EXPECT_NEAR(report.imu_gap_bridged_s, 0.11, 1e-9);
  ASSERT_TRUE(gs.processBatch(restBatch(1, 310000), &report).ok()) << report.reason;
  EXPECT_EQ(report.imu_gap_bridged_s, 0.0);
  EXPECT_EQ(gs.statistics().agents.at(1).imu_gaps_bridged, 1);
  EXPECT_EQ(gs.statistics().rejected(), 0);
  // At rest, the samples bridged between two resting ones keep it at rest.
  EXPECT_LT(gs.estimate(1)->x_v.segment<3>(3).norm(), 1e-6);  // velocity [m/s]

  // A gap beyond cc.max_imu_gap_s: that batch is refused for the propagation, and nothing
  // changed, so a restart (addVehicle) from the agent's estimate takes the next one.
  const VehicleEstimate before = *gs.estimate(1);
  const int64_t later = 310000 + std::llround((defaults.max_imu_gap_s + 0.2) * 1e6);
  EXPECT_FALSE(gs.processBatch(restBatch(1, later), &report).ok());
  EXPECT_EQ(report.refusal, coop::CcRefusal::kPropagation);
  EXPECT_EQ(gs.statistics().agents.at(1).refused.at("propagation"), 1);
  EXPECT_EQ(gs.estimate(1)->x_v, before.x_v);
  ASSERT_TRUE(
      gs.addVehicle(1, StereoCamera(StereoCameraOptions{}), later, before.x_v, before.P_v).ok());
  EXPECT_TRUE(gs.processBatch(restBatch(1, later + 50000), &report).ok()) << report.reason;
}

TEST(CcTeamFilter, VehiclesComeAndGoTheMapStays) {
  coop::CcTeamFilter gs = oneRestingVehicle();
  ASSERT_TRUE(gs.processBatch(restBatch(1, 100000)).ok());
  ASSERT_EQ(gs.map().size(), 1u);
  EXPECT_FALSE(gs.addVehicle(2, StereoCamera(StereoCameraOptions{}), 0, Eigen::VectorXd::Zero(12),
                             Eigen::MatrixXd::Identity(12, 12))
                   .ok())
      << "neither 9 nor 15 entries";
  ASSERT_TRUE(gs.removeVehicle(1).ok());
  EXPECT_FALSE(gs.hasVehicle(1));
  EXPECT_EQ(gs.map().size(), 1u);
  EXPECT_FALSE(gs.map()[0].in_state) << "archived: no UAV keeps it active";
  EXPECT_FALSE(gs.estimate(1).ok());
  EXPECT_FALSE(gs.removeVehicle(1).ok());
}

TEST(CcTeamFilter, LocalIdsMapOnlyWhatTheAgentMapped) {
  // Image sensing (cc.association: local_ids): a batch carries every stereo match, most
  // without an agent landmark id. Only the agent's landmarks enter the joint map, under one
  // joint id per agent id, so that the agent's re-observations are type 1.
  coop::CcTeamFilterOptions o = defaultOptions();
  o.association = coop::CcAssociation::kLocalIds;
  coop::CcTeamFilter gs(o);
  const int n = InsPropagator(o.slam.ins).stateSize();
  ASSERT_TRUE(gs.addVehicle(1, StereoCamera(StereoCameraOptions{}), 0, Eigen::VectorXd::Zero(n),
                            Eigen::MatrixXd::Identity(n, n) * 0.01)
                  .ok());
  for (int64_t t = 100000; t <= 300000; t += 100000) {
    coop::CcObservationBatch b = restBatch(1, t);  // agent landmark 7
    StereoObservation anonymous = b.frame.observations[0];
    anonymous.landmark_id = -1;
    anonymous.index = 9;
    anonymous.z = Eigen::Vector4d(200, 100, 185, 100);
    b.frame.observations.push_back(anonymous);
    coop::CcStepReport report;
    ASSERT_TRUE(gs.processBatch(b, &report).ok()) << report.reason;
    EXPECT_EQ(report.type1 + report.type3, 1) << "the anonymous match is not an observation";
    EXPECT_EQ(report.type1, t == 100000 ? 0 : 1);
  }
  ASSERT_EQ(gs.map().size(), 1u);
  EXPECT_TRUE(gs.map()[0].in_state);
}

TEST(CcTeamFilter, LocalIdsMatchAcrossUavsWithinTheJointCovariance) {
  // UAV2 believes it is 4 m north of where it is and sees UAV1's landmark (same feature index,
  // no descriptor): triangulated from UAV2's estimate the landmark lies 4 m from UAV1's, beyond
  // max_association_distance_m. It is UAV1's landmark (type 2) when the joint covariance allows
  // the offset (UAV2's position σ 5 m), a new one when it does not (σ 0.1 m).
  for (const double sigma : {5.0, 0.1}) {
    SCOPED_TRACE(::testing::Message() << "UAV2 position sigma " << sigma << " m");
    coop::CcTeamFilterOptions o = defaultOptions();
    o.association = coop::CcAssociation::kLocalIds;
    ASSERT_LT(o.max_association_distance_m, 4.0);
    coop::CcTeamFilter gs(o);
    const int n = InsPropagator(o.slam.ins).stateSize();
    const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(n, n) * 0.01;
    ASSERT_TRUE(
        gs.addVehicle(1, StereoCamera(StereoCameraOptions{}), 0, Eigen::VectorXd::Zero(n), P).ok());
    Eigen::VectorXd x2 = Eigen::VectorXd::Zero(n);
    x2(vehicle::kPosition) = 4.0;
    Eigen::MatrixXd P2 = P;
    P2.block<3, 3>(vehicle::kPosition, vehicle::kPosition) =
        Eigen::Matrix3d::Identity() * sigma * sigma;
    ASSERT_TRUE(gs.addVehicle(2, StereoCamera(StereoCameraOptions{}), 0, x2, P2).ok());
    coop::CcStepReport report;
    ASSERT_TRUE(gs.processBatch(restBatch(1, 100000), &report).ok()) << report.reason;
    ASSERT_EQ(report.type3, 1);
    ASSERT_TRUE(gs.processBatch(restBatch(2, 100000), &report).ok()) << report.reason;
    EXPECT_EQ(report.type2, sigma > 1.0 ? 1 : 0);
    EXPECT_EQ(gs.map().size(), sigma > 1.0 ? 1u : 2u);
    // The association is reported once, naming both agents' landmark ids.
    const std::vector<coop::CcCrossAssociation> cross = gs.takeCrossAssociations();
    ASSERT_EQ(cross.size(), sigma > 1.0 ? 1u : 0u);
    if (!cross.empty()) {
      EXPECT_EQ(cross[0].agent, 2);
      EXPECT_EQ(cross[0].local_id, 7);
      EXPECT_EQ(cross[0].mapper, 1);
      EXPECT_EQ(cross[0].mapper_local_id, 7);
    }
    EXPECT_TRUE(gs.takeCrossAssociations().empty());
  }
}

TEST(CcBatchBuilder, BatchHoldsTheImuSinceThePreviousFrame) {
  coop::CcBatchBuilder b(3);
  for (int64_t t : {0, 5000, 10000, 15000}) {
    ImuSample s;
    s.t_us = t;
    b.addImu(s);
  }
  StereoFrameObservations f;
  f.t_us = 10000;
  const coop::CcObservationBatch first = b.takeBatch(f);
  EXPECT_EQ(first.agent_id, 3);
  ASSERT_EQ(first.imu.size(), 3u);
  EXPECT_EQ(first.imu.back().t_us, 10000);
  f.t_us = 20000;
  const coop::CcObservationBatch second = b.takeBatch(f);
  ASSERT_EQ(second.imu.size(), 1u);
  EXPECT_EQ(second.imu[0].t_us, 15000);
  EXPECT_TRUE(coop::validateBatch(second).ok());
  EXPECT_GT(coop::batchPayloadBytes(second), 0);
}

TEST(CcTeamFilterOptions, GroundStationYamlLoadsAndBadValuesFail) {
  auto o = coop::CcTeamFilterOptions::loadFile(std::string(CVSLAM_SOURCE_DIR) +
                                               "/config/ground_station.yaml");
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->association, coop::CcAssociation::kTrueIds);
  // The second-order term as the agents': on with true ids (features), off with image keypoints.
  EXPECT_TRUE(o->slam.slam.second_order_noise);
  EXPECT_TRUE(coop::CcTeamFilter(*o).options().slam.slam.second_order_noise);
  coop::CcTeamFilterOptions images = *o;
  images.association = coop::CcAssociation::kLocalIds;
  EXPECT_FALSE(coop::CcTeamFilter(images).options().slam.slam.second_order_noise);
  images.image_second_order_noise = true;
  EXPECT_TRUE(coop::CcTeamFilter(images).options().slam.slam.second_order_noise);
  // Its mean likewise.
  EXPECT_TRUE(o->slam.slam.second_order_mean);
  EXPECT_TRUE(coop::CcTeamFilter(*o).options().slam.slam.second_order_mean);
  EXPECT_FALSE(coop::CcTeamFilter(images).options().slam.slam.second_order_mean);
  images.image_second_order_mean = true;
  EXPECT_TRUE(coop::CcTeamFilter(images).options().slam.slam.second_order_mean);
  // … and the pixel σ of detected keypoints with local ids, the simulator's with true ids.
  EXPECT_EQ(coop::CcTeamFilter(*o).options().slam.slam.pixel_sigma, o->slam.slam.pixel_sigma);
  EXPECT_LT(o->image_pixel_sigma, o->slam.slam.pixel_sigma);
  EXPECT_EQ(coop::CcTeamFilter(images).options().slam.slam.pixel_sigma, o->image_pixel_sigma);
  auto bad = ConfigNode::fromString("cc: {association: psychic}\n");
  ASSERT_TRUE(bad.ok());
  coop::CcTeamFilterOptions b;
  EXPECT_FALSE(b.load(*bad).ok());
  for (const char* text : {"cc: {max_vehicles: 0}\n", "cc: {image_pixel_sigma: 0}\n"}) {
    auto negative = ConfigNode::fromString(text);
    ASSERT_TRUE(negative.ok());
    coop::CcTeamFilterOptions n;
    EXPECT_FALSE(n.load(*negative).ok()) << text;
  }
}

}  // namespace
}  // namespace cvslam
