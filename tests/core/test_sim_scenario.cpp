// Scenario files and the simulator (cvslam/scenario/scenario.h, simulator.h): loader errors, the
// shipped scenarios, thesis §6.4 geometry (Fig. 6.5), stream order, determinism, speed.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario_setup/scenario_calibration.h"
#include "cvslam/sim/simulator.h"
#include "test_paths.h"

namespace cvslam::sim {
namespace {

std::string scenarioPath(const std::string& name) {
  return test::sourceDir() + "/config/scenarios/" + name;
}

TEST(SimScenario, ShippedScenariosLoad) {
  for (const char* name : {"thesis_loop.yaml", "single_circle.yaml", "team3_aerial.yaml"}) {
    auto s = Scenario::loadFile(scenarioPath(name));
    ASSERT_TRUE(s.ok()) << s.status().message();
    EXPECT_FALSE(s->agents.empty());
  }
  auto t = Scenario::loadFile(scenarioPath("thesis_loop.yaml"));
  ASSERT_EQ(t->agents.size(), 2u);
  EXPECT_EQ(t->agents[1].imu.rate_hz, 200.0);  // YAML alias of agent 1's section
  EXPECT_EQ(t->agents[1].pixel_noise.kind, NoiseKind::kGaussian);
  EXPECT_EQ(Scenario::loadFile(scenarioPath("team3_aerial.yaml"))->agents.size(), 3u);
}

// First error of a scenario given as text.
std::string loadError(const std::string& yaml) {
  auto s = Scenario::fromString(yaml, "bad.yaml");
  return s.ok() ? std::string() : s.status().message();
}

TEST(SimScenario, LoaderErrorsNameFileAndKey) {
  const std::string agent = "agents: [{id: 1, trajectory: {kind: circle, radius: 20}}]\n";
  EXPECT_EQ(loadError(agent), "");
  EXPECT_EQ(loadError("duration: -1\n" + agent).rfind("bad.yaml: duration: must be > 0", 0), 0u);
  EXPECT_EQ(loadError("seed: 1\n").rfind("bad.yaml: agents: required key is missing", 0), 0u);
  EXPECT_EQ(loadError("agents: [{id: 1, trajectory: {kind: spiral}}]")
                .rfind("bad.yaml: agents[0].trajectory.kind: must be one of", 0),
            0u);
  EXPECT_EQ(loadError("agents: [{id: 1, trajectory: {kind: circle, radius: 20, radus: 3}}]"),
            "bad.yaml: agents[0].trajectory.radus: unknown key");
  EXPECT_EQ(loadError("agents: [{id: 1, pixel_noise: {kind: laplace}}]")
                .rfind("bad.yaml: agents[0].pixel_noise.kind: must be one of gaussian, "
                       "non_gaussian_centred, non_centred",
                       0),
            0u);
  EXPECT_EQ(loadError("agents: [{id: 1}, {id: 1}]"),
            "bad.yaml: agents[1].id: duplicate agent id 1");
  EXPECT_EQ(loadError("agents: [{id: 1, camera: {baseline: 0}}]"),
            "bad.yaml: agents[0].camera.baseline: must be > 0");
  EXPECT_EQ(loadError("agents: [{id: 1, imu: {rate_hz: 0}}]")
                .rfind("bad.yaml: agents[0].imu.rate_hz: must be in", 0),
            0u);
  EXPECT_EQ(loadError("duration: 100\nagents: [{id: 1, trajectory: {kind: waypoints, speed: 2, "
                      "points: [{p: [0, 0, -10]}, {p: [20, 0, -10]}]}}]")
                .rfind("bad.yaml: agents[0].trajectory: trajectory lasts 10", 0),
            0u);
  const std::string tum_error =
      loadError("agents: [{id: 1, trajectory: {kind: tum, file: nope.tum}}]");
  EXPECT_EQ(tum_error.rfind("bad.yaml: agents[0].trajectory: ", 0), 0u) << tum_error;
  EXPECT_NE(tum_error.find("nope.tum: cannot open"), std::string::npos) << tum_error;
  auto missing = Scenario::loadFile("/nonexistent/scenario.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("/nonexistent/scenario.yaml"), std::string::npos);
}

// Thesis §6.4, Fig. 6.5: UAV1 closes its loop at 200 s (and not before ~190 s); UAV2 crosses
// UAV1 at ≈80 s and ≈150 s and never revisits its own area.
TEST(SimScenario, ThesisLoopGeometry) {
  auto sc = Scenario::loadFile(scenarioPath("thesis_loop.yaml"));
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  auto t1 = sc->agents[0].trajectory.build();
  auto t2 = sc->agents[1].trajectory.build();
  ASSERT_TRUE(t1.ok() && t2.ok());
  const auto p1 = [&](double t) { return Eigen::Vector2d((*t1)->state(t).p_BinN.head<2>()); };
  const auto p2 = [&](double t) { return Eigen::Vector2d((*t2)->state(t).p_BinN.head<2>()); };
  // Loop closure.
  EXPECT_LT((p1(200) - p1(0)).norm(), 1.0);
  for (double t = 15; t <= 190; t += 0.5) EXPECT_GT((p1(t) - p1(0)).norm(), 25.0) << t;
  // Crossings: same ground at the same time (the cameras see ~6 m × 4 m each).
  for (double t : {80.0, 150.0}) EXPECT_LT((p1(t) - p2(t)).norm(), 1.0) << t;
  for (double t = 0; t <= 210; t += 0.5) {
    if (std::abs(t - 80) > 10 && std::abs(t - 150) > 10) {
      EXPECT_GT((p1(t) - p2(t)).norm(), 20.0) << t;
    }
  }
  // UAV2 never comes back over ground it saw more than 20 s earlier.
  double closest = 1e9;
  for (double t = 0; t <= 210; t += 1.0)
    for (double s = 0; s + 20 <= t; s += 1.0) closest = std::min(closest, (p2(t) - p2(s)).norm());
  EXPECT_GT(closest, 40.0);
  // Both fly at a few m/s, ~10 m above the ground.
  for (double t = 0; t <= 210; t += 1.0) {
    for (const auto* traj : {&*t1, &*t2}) {
      const TrajectoryState s = (*traj)->state(t);
      EXPECT_GT(s.v_N.norm(), 1.5);
      EXPECT_LT(s.v_N.norm(), 6.0);
      EXPECT_NEAR(-s.p_BinN.z(), 11.0, 2.1);
    }
  }
}

TEST(SimSimulator, StreamIsOrderedAndComplete) {
  auto sc = Scenario::loadFile(scenarioPath("single_circle.yaml"));
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  sc->duration = 5.0;
  auto sim = Simulator::create(*sc);
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  SimEvent e;
  int64_t last = -1;
  int imu = 0, frames = 0;
  SensorEventType last_type = SensorEventType::kFeatures;
  while (sim->next(e)) {
    EXPECT_GE(e.t_us, last);
    if (e.t_us == last) {
      EXPECT_FALSE(e.type == SensorEventType::kImu && last_type == SensorEventType::kFeatures);
    }
    last = e.t_us;
    last_type = e.type;
    if (e.type == SensorEventType::kImu) {
      ++imu;
      EXPECT_EQ(e.imu.t_us, e.t_us);
    } else {
      ++frames;
      EXPECT_EQ(e.frame.t_us, e.t_us);
      EXPECT_EQ(e.truth.t_us, e.t_us);
      EXPECT_FALSE(e.frame.observations.empty());
      // Ground truth in filter terms: v_B is the body velocity.
      const TrajectoryState s = sim->agent(0).trajectory().state(e.t_us * 1e-6);
      EXPECT_LT((e.truth.v_B - s.R_NtoB * s.v_N).norm(), 1e-12);
      EXPECT_GT(e.truth.v_B.x(), 2.5);  // flying forward at 3 m/s
    }
  }
  EXPECT_EQ(imu, 1001);    // 200 Hz over [0, 5] s inclusive
  EXPECT_EQ(frames, 101);  // 20 Hz
  EXPECT_EQ(last, 5000000);
  ASSERT_NE(sim->agentById(1), nullptr);
  EXPECT_EQ(sim->agentById(2), nullptr);
}

// Drains a simulator into a digest of everything it emitted.
std::vector<double> digest(Simulator& sim, int agent_id) {
  std::vector<double> d;
  SimEvent e;
  while (sim.next(e)) {
    if (e.agent_id != agent_id) continue;
    if (e.type == SensorEventType::kImu) {
      for (int i = 0; i < 3; ++i) d.push_back(e.imu.accel_B(i) + e.imu.gyro_B(i));
    } else {
      for (const auto& o : e.frame.observations) d.push_back(o.index + o.z.sum());
    }
  }
  return d;
}

TEST(SimSimulator, DeterministicAndIndependentPerAgent) {
  auto sc = Scenario::loadFile(scenarioPath("team3_aerial.yaml"));
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  sc->duration = 4.0;
  auto a = Simulator::create(*sc), b = Simulator::create(*sc);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(digest(*a, 1), digest(*b, 1));  // same seed ⇒ identical streams
  // Different agents flying the same path get different noise.
  Scenario same = *sc;
  same.agents[1].trajectory = same.agents[0].trajectory;
  auto c = Simulator::create(same);
  ASSERT_TRUE(c.ok());
  SimEvent e1, e2;
  ASSERT_TRUE(c->agent(0).next(e1) && c->agent(1).next(e2));
  EXPECT_EQ(e1.t_us, e2.t_us);
  EXPECT_NE(e1.imu.accel_B, e2.imu.accel_B);
  // Another seed, other noise.
  Scenario other = *sc;
  other.seed += 1;
  auto d = Simulator::create(other);
  auto again = Simulator::create(*sc);
  ASSERT_TRUE(d.ok() && again.ok());
  EXPECT_NE(digest(*d, 1), digest(*again, 1));
}

TEST(SimSimulator, PartOfTheTeamOrOfTheRunFliesInTheSameWorld) {
  // cvslam_run --agents / --duration run a part of the scenario: the landmarks must be those of
  // the full run (once, another layout made a UAV of euroc_mh03_hall look 8 cm or 900 m off).
  auto sc = Scenario::loadFile(scenarioPath("euroc_mh03_hall.yaml"));
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  auto full = Simulator::create(*sc);
  Scenario part = *sc;
  part.agents.resize(1);
  part.duration = 20.0;
  auto partial = Simulator::create(part);
  ASSERT_TRUE(full.ok() && partial.ok());
  ASSERT_EQ(full->landmarks().size(), partial->landmarks().size());
  for (std::size_t i = 0; i < full->landmarks().size(); i += 97)
    EXPECT_EQ(full->landmarks()[i].p_LinN, partial->landmarks()[i].p_LinN) << i;
  // Without the whole team's flights (a hand-made scenario), the agents' own define the area.
  part.world_region.setEmpty();
  auto own = Simulator::create(part);
  ASSERT_TRUE(own.ok());
  EXPECT_LT(own->landmarks().size(), full->landmarks().size());
}

TEST(SimSimulator, ThesisLoopSpeed) {
  auto sc = Scenario::loadFile(scenarioPath("thesis_loop.yaml"));
  ASSERT_TRUE(sc.ok());
  sc->duration = 60.0;
  const auto start = std::chrono::steady_clock::now();
  auto sim = Simulator::create(*sc);
  ASSERT_TRUE(sim.ok());
  const auto built = std::chrono::steady_clock::now();
  SimEvent e;
  std::size_t obs = 0, frames = 0;
  while (sim->next(e)) {
    if (e.type == SensorEventType::kFeatures) {
      obs += e.frame.observations.size();
      ++frames;
    }
  }
  const auto done = std::chrono::steady_clock::now();
  const double build_s = std::chrono::duration<double>(built - start).count();
  const double run_s = std::chrono::duration<double>(done - built).count();
  std::printf(
      "thesis_loop: %zu landmarks, world %.3f s; 60 s of flight for 2 agents: %.3f s, "
      "%.1f observations per frame\n",
      sim->landmarks().size(), build_s, run_s,
      static_cast<double>(obs) / static_cast<double>(frames));
  EXPECT_GT(static_cast<double>(obs) / static_cast<double>(frames), 5.0);
  EXPECT_LT(run_s, 5.0);  // generous for loaded CI machines; typically far below 1 s
}

TEST(SimSimulator, InitialEstimateIsTruthOrASampleAroundIt) {
  auto sc = Scenario::loadFile(scenarioPath("single_circle.yaml"));
  ASSERT_TRUE(sc.ok());
  sc->duration = 1.0;
  // Perturbed by default (an estimator never starts at the truth); exact with perturb: false.
  EXPECT_TRUE(sc->agents[0].initial.perturb);
  sc->agents[0].initial.perturb = false;
  auto exact = Simulator::create(*sc);
  ASSERT_TRUE(exact.ok());
  const GroundTruth truth = exact->agent(0).truth(0);
  EXPECT_EQ(exact->agent(0).initialEstimate().state.p_BinN, truth.p_BinN);
  EXPECT_EQ(exact->agent(0).initialEstimate().state.euler, truth.euler);
  // Perturbed: errors of the configured size, over many seeds.
  sc->agents[0].initial.perturb = true;
  sc->agents[0].initial.position_sigma = Eigen::Vector3d(1.0, 2.0, 0.5);
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero();
  const int runs = 300;
  for (int r = 0; r < runs; ++r) {
    sc->seed = 100 + static_cast<uint64_t>(r);
    auto sim = Simulator::create(*sc);
    ASSERT_TRUE(sim.ok());
    const Eigen::Vector3d e = sim->agent(0).initialEstimate().state.p_BinN - truth.p_BinN;
    sum2 += e.cwiseProduct(e);
  }
  const Eigen::Vector3d stdv = (sum2 / runs).cwiseSqrt();
  EXPECT_NEAR(stdv.x(), 1.0, 0.15);
  EXPECT_NEAR(stdv.y(), 2.0, 0.3);
  EXPECT_NEAR(stdv.z(), 0.5, 0.075);
}

TEST(SimSimulator, PerturbedBiasesAreDrawnFromTheFiltersStatedSigma) {
  // perturb_biases: the filter's initial bias estimates scatter around the IMU's true turn-on
  // biases with the σ the filter states (slam.initial_*_bias_sigma); the pose draws are those
  // of perturb alone. Without it the filter starts at slam.initial_*_bias.
  auto sc = Scenario::loadFile(scenarioPath("single_circle.yaml"));
  ASSERT_TRUE(sc.ok());
  sc->duration = 1.0;
  sc->agents[0].imu.accel_bias = Eigen::Vector3d(0.02, -0.01, 0.03);
  VisualInertialSlamOptions options;
  options.ins.estimate_imu_bias = true;
  options.slam.initial_accel_bias_sigma = 0.05;
  options.slam.initial_gyro_bias_sigma = 0.002;
  Eigen::Vector3d sum_a = Eigen::Vector3d::Zero(), sum2_a = sum_a, sum2_g = sum_a;
  const int runs = 300;
  for (int r = 0; r < runs; ++r) {
    sc->seed = 500 + static_cast<uint64_t>(r);
    sc->agents[0].initial.perturb_biases = false;
    auto plain = Simulator::create(*sc);
    ASSERT_TRUE(plain.ok());
    const AgentFilterSetup p = simulatedAgentSetup(plain->agent(0).scenarioAgent(), options);
    EXPECT_TRUE(p.x0.segment<6>(vehicle::kAccelBias).isZero());
    sc->agents[0].initial.perturb_biases = true;
    auto drawn = Simulator::create(*sc);
    ASSERT_TRUE(drawn.ok());
    const AgentFilterSetup d = simulatedAgentSetup(drawn->agent(0).scenarioAgent(), options);
    EXPECT_EQ(d.x0.head<9>(), p.x0.head<9>());  // the same pose draws
    const Eigen::Vector3d ea = d.x0.segment<3>(vehicle::kAccelBias) - sc->agents[0].imu.accel_bias;
    const Eigen::Vector3d eg = d.x0.segment<3>(vehicle::kGyroBias);  // true gyro bias 0
    sum_a += ea;
    sum2_a += ea.cwiseProduct(ea);
    sum2_g += eg.cwiseProduct(eg);
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(std::sqrt(sum2_a(i) / runs), 0.05, 0.0075);
    EXPECT_NEAR(std::sqrt(sum2_g(i) / runs), 0.002, 0.0003);
    EXPECT_LT(std::abs(sum_a(i) / runs), 3.0 * 0.05 / std::sqrt(runs));  // around the truth
  }
}

TEST(SimScenario, LoopSpeedSetsThePeriod) {
  auto s = Scenario::fromString(
      "agents: [{id: 1, trajectory: {kind: circle, radius: 30, speed: 3}}]", "t.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_NEAR(s->agents[0].trajectory.loop.period, 2 * M_PI * 30 / 3, 1e-9);
  auto traj = s->agents[0].trajectory.build();
  EXPECT_NEAR((*traj)->state(7.0).v_N.norm(), 3.0, 1e-9);
}

// End to end on the observations: UAV1 re-observes its own old landmarks only when it closes
// the loop (≈200 s); UAV2 sees landmarks UAV1 saw only around 80 s and 150 s and never
// re-observes its own old ones (thesis §6.4, Fig. 6.5).
TEST(SimSimulator, ThesisLoopSharedAndReobservedLandmarks) {
  auto sc = Scenario::loadFile(scenarioPath("thesis_loop.yaml"));
  ASSERT_TRUE(sc.ok());
  auto sim = Simulator::create(*sc);
  ASSERT_TRUE(sim.ok());
  const std::size_t n = sim->landmarks().size();
  // First time each agent saw each landmark [s], or −1.
  std::vector<double> first1(n, -1.0), first2(n, -1.0);
  std::vector<double> uav1_loop_times, uav2_own_revisits, shared_times;
  SimEvent e;
  while (sim->next(e)) {
    if (e.type != SensorEventType::kFeatures) continue;
    const double t = 1e-6 * static_cast<double>(e.t_us);
    auto& mine = e.agent_id == 1 ? first1 : first2;
    for (const auto& o : e.frame.observations) {
      double& f = mine[o.index];
      if (f < 0) f = t;
      if (t - f > 30.0) (e.agent_id == 1 ? uav1_loop_times : uav2_own_revisits).push_back(t);
      if (e.agent_id == 2 && first1[o.index] >= 0) shared_times.push_back(t);
    }
  }
  ASSERT_FALSE(uav1_loop_times.empty());
  EXPECT_GT(*std::min_element(uav1_loop_times.begin(), uav1_loop_times.end()), 195.0);
  EXPECT_TRUE(uav2_own_revisits.empty());
  ASSERT_FALSE(shared_times.empty());
  int near80 = 0, near150 = 0;
  for (double t : shared_times) {
    EXPECT_TRUE(std::abs(t - 80.0) < 5.0 || std::abs(t - 150.0) < 5.0) << t;
    near80 += std::abs(t - 80.0) < 5.0;
    near150 += std::abs(t - 150.0) < 5.0;
  }
  EXPECT_GT(near80, 10);
  EXPECT_GT(near150, 10);
}

}  // namespace
}  // namespace cvslam::sim
