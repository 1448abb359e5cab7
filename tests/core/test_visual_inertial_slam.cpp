// VisualInertialSlam on feature-level simulations (fixed seeds): accuracy against INS-only
// dead reckoning, consistency, k-nearest map management bounds, loop closing, EKF ≡ NH∞ as
// θ → 0, and input errors.

#include "cvslam/slam/visual_inertial_slam.h"
#include "shipped_config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/io/config_node.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/visual_slam_pipeline.h"
#include "nees_band.h"

namespace cvslam {
namespace {

// A 25 m-radius circle at 10 m height, 3 m/s (one lap ≈ 52 s), 10 Hz stereo.
std::string circleScenario(double duration, uint64_t seed, const std::string& noise = "gaussian",
                           double sigma_px = 0.5) {
  return "name: test_circle\nseed: " + std::to_string(seed) +
         "\nduration: " + std::to_string(duration) +
         "\nworld: {relief_amplitude: 1.0, landmark_density: 0.5, margin: 30.0}\n"
         "agents:\n"
         "  - id: 1\n"
         "    trajectory: {kind: circle, centre: [0.0, 0.0], radius: 25.0, altitude: 10.0, "
         "speed: 3.0, heading: velocity, tilt: bank}\n"
         "    camera_rate_hz: 10.0\n"
         "    pixel_noise: {kind: " +
         noise + ", sigma_px: " + std::to_string(sigma_px) + "}\n";
}

sim::Scenario loadScenario(const std::string& yaml) {
  auto s = sim::Scenario::fromString(yaml, "test.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return *s;
}

struct RunErrors {
  std::vector<double> t, slam_error, ins_error, nees_position;
  std::vector<double> nees_vehicle;  ///< 9 dof: position, body velocity, Euler angles
  std::vector<int> state_size, initialised;
  int loop_frames = 0;
  int reactivated = 0;
  double first_loop_t = -1.0;
  int frames = 0;
  double nis = 0.0;  ///< Σ of the frames' joint NIS
  int nis_dof = 0;   ///< Σ of their degrees of freedom

  double rms(const std::vector<double>& e) const {
    double s = 0.0;
    for (double x : e) s += x * x;
    return std::sqrt(s / static_cast<double>(e.size()));
  }
  double meanVehicleNees() const {
    double s = 0.0;
    for (double v : nees_vehicle) s += v;
    return s / static_cast<double>(nees_vehicle.size());
  }
  /// Mean error over frames with t in [t0, t1).
  double meanError(double t0, double t1) const {
    double s = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t0 && t[i] < t1) s += slam_error[i], ++n;
    return n > 0 ? s / n : NAN;
  }
};

const std::string kHallScenario =
    std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/euroc_mh03_hall.yaml";

/// The options of the shipped config/agent.yaml.
bool loadShippedOptions(VisualInertialSlamOptions* o) {
  auto shipped = test::shippedAgentConfig();
  EXPECT_TRUE(shipped.ok()) << shipped.status().message();
  if (!shipped.ok()) return false;
  const Status s = o->load(*shipped);
  EXPECT_TRUE(s.ok()) << s.message();
  return s.ok();
}

RunErrors runScenario(const sim::Scenario& scenario, const VisualInertialSlamOptions& options) {
  RunErrors out;
  auto run = SimulatedTeamRun::create(scenario, options);
  EXPECT_TRUE(run.ok()) << run.status().message();
  if (!run.ok()) return out;
  Status s = (*run)->run([&](const SimulatedFrame& f) {
    const double t = static_cast<double>(f.t_us) * 1e-6;
    const Eigen::VectorXd x = f.slam->vehicleState();
    const Eigen::Vector3d e = x.head<3>() - f.truth->p_BinN;
    const Eigen::Matrix3d P = f.slam->vehicleCovariance().topLeftCorner<3, 3>();
    out.t.push_back(t);
    out.slam_error.push_back(e.norm());
    Eigen::Matrix<double, 9, 1> ev;
    ev << e, x.segment<3>(3) - f.truth->v_B, x.segment<3>(6) - f.truth->euler;
    ev(8) = std::remainder(ev(8), 2.0 * M_PI);
    out.nees_vehicle.push_back(
        ev.dot(f.slam->vehicleCovariance().topLeftCorner<9, 9>().ldlt().solve(ev)));
    out.ins_error.push_back((f.x_ins->head<3>() - f.truth->p_BinN).norm());
    out.nees_position.push_back(e.dot(P.ldlt().solve(e)));
    out.state_size.push_back(f.report->state_size);
    out.initialised.push_back(f.report->initialised);
    out.reactivated += f.report->reactivated;
    out.nis += f.report->nis;
    out.nis_dof += f.report->nis_dof;
    if (f.report->loop_closure) {
      ++out.loop_frames;
      if (out.first_loop_t < 0) out.first_loop_t = t;
    }
    ++out.frames;
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

TEST(VisualInertialSlam, BeatsDeadReckoningAndStaysConsistent) {
  // The shipped configuration (config/agent.yaml) from perturbed starts (the scenarios'
  // default), seeds 11-13: the position error far below the INS's (measured 0.78 against 64 m),
  // and the three runs' mean 9-dof vehicle NEES and 3-dof position NEES inside their χ² bands
  // (tests/core/nees_band.h; measured 7.2 in [4.86, 14.40] and 2.8 in [0.90, 6.34]). (The C++
  // defaults, without bias states, are not: vehicle NEES 870 from the truth or perturbed.)
  VisualInertialSlamOptions shipped;
  ASSERT_TRUE(loadShippedOptions(&shipped));
  double slam = 0.0, ins = 0.0, nees = 0.0, nees_position = 0.0;
  const std::vector<uint64_t> seeds = {11, 12, 13};
  const auto n = static_cast<double>(seeds.size());
  for (uint64_t seed : seeds) {
    const RunErrors r = runScenario(loadScenario(circleScenario(40.0, seed)), shipped);
    ASSERT_GT(r.frames, 350);
    slam += r.rms(r.slam_error) / n;
    ins += r.rms(r.ins_error) / n;
    nees += r.meanVehicleNees() / n;
    double p = 0.0;
    for (double v : r.nees_position) p += v;
    nees_position += p / static_cast<double>(r.nees_position.size()) / n;
  }
  RecordProperty("slam_rmse_m", std::to_string(slam));
  RecordProperty("ins_rmse_m", std::to_string(ins));
  RecordProperty("vehicle_nees", std::to_string(nees));
  RecordProperty("position_nees", std::to_string(nees_position));
  EXPECT_LT(slam, 0.2 * ins) << "VSLAM " << slam << " m vs INS " << ins << " m";
  const test::NeesBand vehicle = test::neesBand(9, static_cast<int>(seeds.size()));
  EXPECT_TRUE(vehicle.contains(nees)) << "mean vehicle NEES " << nees << ", band " << vehicle.str();
  const test::NeesBand position = test::neesBand(3, static_cast<int>(seeds.size()));
  EXPECT_TRUE(position.contains(nees_position))
      << "mean position NEES " << nees_position << ", band " << position.str();
}

TEST(VisualInertialSlam, FrameNisTellsWhetherThePixelNoiseIsStatedRight) {
  // The per-frame NIS (FrameReport::nis, events.csv) is the consistency check a recording
  // allows: pooled over a run, Σ nis / Σ dof ≈ 1 when the filter's pixel σ is the images' and
  // ≈ 2 when their σ is √2 times the stated one (seeds 13, 14: no default chosen on them).
  // (At twice the stated σ the gate refuses nearly everything within a second and the filter
  // is lost: over-confidence feeds itself.)
  for (uint64_t seed : {13u, 14u}) {
    const RunErrors right = runScenario(loadScenario(circleScenario(20.0, seed)), {});
    const RunErrors noisy =
        runScenario(loadScenario(circleScenario(20.0, seed, "gaussian", 0.7)), {});
    ASSERT_GT(right.nis_dof, 1000);
    ASSERT_GT(noisy.nis_dof, 1000) << noisy.frames << " frames";
    const double r = right.nis / right.nis_dof, n = noisy.nis / noisy.nis_dof;
    RecordProperty("nis_per_dof_seed" + std::to_string(seed), std::to_string(r));
    EXPECT_GT(r, 0.7) << "seed " << seed;
    EXPECT_LT(r, 1.3) << "seed " << seed;
    RecordProperty("nis_per_dof_noisy_seed" + std::to_string(seed), std::to_string(n));
    EXPECT_GT(n, 1.5) << "seed " << seed << ": pixel noise √2 times the stated σ";
  }
}

TEST(VisualInertialSlam, KNearestBoundsTheStateAndClosesTheLoop) {
  // The loop's mechanics (detection, the iterated update) with every re-entry intersected: the
  // drift here is too small for the agents' default to re-enter anything (next test).
  VisualInertialSlamOptions o;
  o.map.k = 20;
  o.slam.intersection.remap_without_gain = false;
  o.slam.intersection.objective = ReactivationOptions::Objective::kPositionTrace;
  const RunErrors r = runScenario(loadScenario(circleScenario(70.0, 5)), o);
  ASSERT_FALSE(r.state_size.empty());
  for (std::size_t i = 0; i < r.state_size.size(); ++i) {
    ASSERT_LE(r.state_size[i], 9 + 3 * (o.map.k + r.initialised[i] + o.slam.held_landmarks))
        << "frame " << i;
  }
  // One lap takes 2π·25/3 ≈ 52.4 s: the first landmarks come back then.
  EXPECT_GT(r.first_loop_t, 45.0);
  EXPECT_LT(r.first_loop_t, 60.0);
  // With the observability-constrained filter the drift before the loop is ≈ 0.2 m (1.2 m
  // without), so the loop has little left to correct; it must not disturb the estimate.
  EXPECT_LT(r.meanError(r.first_loop_t + 2.0, r.first_loop_t + 6.0), 0.35);
  EXPECT_LT(r.meanError(r.first_loop_t - 6.0, r.first_loop_t - 2.0), 0.35);
}

TEST(VisualInertialSlam, WithoutGainTheSecondLapMapsAnew) {
  // The defaults on the same lap: ≈ 0.2 m of drift gives the archive next to nothing to tell
  // that the intersection's 1/ω would not cost the rest of the vehicle block more, so most
  // returning landmarks are mapped anew (ReactivationOptions::remap_without_gain) and no loop
  // is closed; the error stays as small as with the loop.
  VisualInertialSlamOptions o;
  o.map.k = 20;
  const RunErrors r = runScenario(loadScenario(circleScenario(70.0, 5)), o);
  o.slam.intersection.remap_without_gain = false;
  const RunErrors always = runScenario(loadScenario(circleScenario(70.0, 5)), o);
  std::cout << "re-activated " << r.reactivated << " (always intersecting: " << always.reactivated
            << "), loop frames " << r.loop_frames << "\n";
  EXPECT_LT(10 * r.reactivated, always.reactivated);
  EXPECT_EQ(r.loop_frames, 0);
  EXPECT_LT(r.meanError(55.0, 65.0), 0.35);
}

TEST(VisualInertialSlam, FullMapGrowsWithTheLandmarksSeen) {
  VisualInertialSlamOptions o;
  o.map.kind = MapKind::kFull;
  auto run = SimulatedTeamRun::create(loadScenario(circleScenario(15.0, 3)), o);
  ASSERT_TRUE(run.ok());
  int total_new = 0, last_size = 0;
  ASSERT_TRUE((*run)
                  ->run([&](const SimulatedFrame& f) {
                    total_new += f.report->initialised;
                    last_size = f.report->state_size;
                    EXPECT_EQ(f.report->archived, 0);
                    return Status::Ok();
                  })
                  .ok());
  EXPECT_EQ(last_size, 9 + 3 * total_new);
  EXPECT_GT(total_new, 60);
  EXPECT_EQ((*run)->slam(0).archive().size(), 0u);
}

TEST(VisualInertialSlam, HoveringVehicleWithHeldLandmarksStaysInsideTheNeesBand) {
  // MH_01 in the hall (features): 20 s at rest, then the flight, before any landmark is 30 s
  // unseen. At rest ~40 landmarks are visible, k = 20 are in the state: they leave and come
  // back every few frames, as held landmarks (slam.held_landmarks), exactly. Perturbed starts,
  // seeds no default was chosen on. Held landmarks alone (without slam.anchor_landmarks) and
  // the shipped configuration (with them): the state stays bounded, the held landmarks come
  // back more often than there are frames, and the 8 runs' mean 9-dof vehicle NEES is inside
  // their χ² band ([6.30, 12.17]; measured 8.80 held, 9.31 shipped). Re-mapping the returning
  // landmarks instead measured 8.97 on the same runs: that held landmarks make the filter more
  // consistent is not shown by this flight, and not asserted.
  auto hall = sim::Scenario::loadFile(kHallScenario);
  ASSERT_TRUE(hall.ok()) << hall.status().message();
  hall->agents.resize(1);
  hall->duration = 40.0;
  VisualInertialSlamOptions shipped;
  ASSERT_TRUE(loadShippedOptions(&shipped));
  ASSERT_GT(shipped.slam.anchor_landmarks, 0);
  ASSERT_GT(shipped.slam.held_landmarks, 0);
  VisualInertialSlamOptions held = shipped;  // the shipped count of recent held landmarks
  held.slam.anchor_landmarks = 0;
  double nees_held = 0.0, nees_shipped = 0.0;
  const std::vector<uint64_t> seeds = {21, 22, 23, 24, 25, 26, 27, 28};
  const auto n = static_cast<double>(seeds.size());
  for (uint64_t seed : seeds) {
    hall->seed = seed;
    const RunErrors b = runScenario(*hall, held), c = runScenario(*hall, shipped);
    ASSERT_GT(b.frames, 700);
    EXPECT_GT(b.reactivated, b.frames) << "seed " << seed;
    for (std::size_t i = 0; i < c.state_size.size(); ++i) {
      ASSERT_LE(c.state_size[i],
                15 + 3 * (shipped.map.k + c.initialised[i] + shipped.slam.held_landmarks +
                          shipped.slam.anchor_landmarks))
          << "frame " << i;
    }
    nees_held += b.meanVehicleNees() / n;
    nees_shipped += c.meanVehicleNees() / n;
    std::cout << "seed " << seed << ": vehicle NEES held " << b.meanVehicleNees()
              << ", with anchors " << c.meanVehicleNees() << "\n";
  }
  const test::NeesBand band = test::neesBand(9, static_cast<int>(seeds.size()));
  RecordProperty("nees_held", std::to_string(nees_held));
  RecordProperty("nees_shipped", std::to_string(nees_shipped));
  EXPECT_TRUE(band.contains(nees_held)) << "held: " << nees_held << ", band " << band.str();
  EXPECT_TRUE(band.contains(nees_shipped))
      << "shipped: " << nees_shipped << ", band " << band.str();
}

TEST(VisualInertialSlam, FullMapOfAHallFlightStaysInsideItsNeesBand) {
  // MH_02 in the hall (features) with the full map, the map one vehicle inside one room runs
  // (scripts/run_dataset.sh --map room, at most 500 landmarks): hundreds of landmarks
  // re-observed. The shipped configuration otherwise, perturbed starts and drawn biases (the
  // scenarios' defaults), seeds no setting was chosen on: the runs' mean 9-dof vehicle NEES
  // inside their χ² band ([4.12, 15.76]; measured 12.9) and the position RMS error under 0.4 m
  // (0.26 m). (The additive chart's tilt
  // constraint against first-estimate Jacobians on this flight, 80 s: scripts/
  // tilt_constraint_figures.sh.)
  auto hall = sim::Scenario::loadFile(kHallScenario);
  ASSERT_TRUE(hall.ok()) << hall.status().message();
  hall->agents.erase(hall->agents.begin());
  hall->agents.resize(1);
  hall->duration = 20.0;
  VisualInertialSlamOptions room;
  ASSERT_TRUE(loadShippedOptions(&room));
  room.map.kind = MapKind::kFull;
  room.map.max_landmarks = 500;
  const std::vector<uint64_t> seeds = {43, 44};
  const auto n = static_cast<double>(seeds.size());
  double nees = 0.0, rms = 0.0;
  int max_state = 0;
  for (uint64_t seed : seeds) {
    hall->seed = seed;
    const RunErrors r = runScenario(*hall, room);
    ASSERT_GT(r.frames, 190);
    nees += r.meanVehicleNees() / n;
    rms += r.rms(r.slam_error) / n;
    max_state = std::max(max_state, *std::max_element(r.state_size.begin(), r.state_size.end()));
    std::cout << "seed " << seed << ": vehicle NEES " << r.meanVehicleNees() << ", RMS "
              << r.rms(r.slam_error) << " m\n";
  }
  const test::NeesBand band = test::neesBand(9, static_cast<int>(seeds.size()));
  RecordProperty("vehicle_nees", std::to_string(nees));
  RecordProperty("rms_m", std::to_string(rms));
  EXPECT_GT(max_state, 15 + 3 * 150) << "the full map holds the landmarks seen";
  EXPECT_TRUE(band.contains(nees)) << "mean vehicle NEES " << nees << ", band " << band.str();
  EXPECT_LT(rms, 0.4);
}

TEST(VisualInertialSlam, NhinfWithVanishingThetaIsTheEkf) {
  const sim::Scenario sc = loadScenario(circleScenario(8.0, 2));
  VisualInertialSlamOptions ekf, nhinf;
  nhinf.filter.type = FilterType::kNhinf;
  nhinf.filter.gamma = 1e9;  // θ = 1e-18
  const RunErrors a = runScenario(sc, ekf), b = runScenario(sc, nhinf);
  ASSERT_EQ(a.slam_error.size(), b.slam_error.size());
  for (std::size_t i = 0; i < a.slam_error.size(); ++i) {
    ASSERT_NEAR(a.slam_error[i], b.slam_error[i], 1e-6) << "frame " << i;
  }
}

TEST(VisualInertialSlam, RejectsBadInput) {
  VisualInertialSlam slam({}, StereoCamera());
  EXPECT_FALSE(slam.processFrame({}).ok());
  EXPECT_FALSE(slam.addImu({}).ok());
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(9);
  x0(2) = -10.0;
  EXPECT_FALSE(slam.initialize(0, Eigen::VectorXd::Zero(4), Eigen::MatrixXd::Identity(4, 4)).ok());
  ASSERT_TRUE(slam.initialize(0, x0, Eigen::MatrixXd::Identity(9, 9) * 0.01).ok());
  ImuSample s;
  s.t_us = 5000;
  s.accel_B = Eigen::Vector3d(0, 0, -9.81);
  EXPECT_TRUE(slam.addImu(s).ok());
  EXPECT_FALSE(slam.addImu(s).ok()) << "repeated timestamp";
  s.t_us = 10000;
  s.gyro_B(0) = NAN;
  EXPECT_FALSE(slam.addImu(s).ok()) << "non-finite sample";
  StereoFrameObservations frame;
  frame.t_us = 5000;
  StereoObservation obs;
  obs.z = Eigen::Vector4d(100, 100, NAN, 100);
  frame.observations.push_back(obs);
  EXPECT_FALSE(slam.processFrame(frame).ok());
  frame.observations.clear();
  EXPECT_TRUE(slam.processFrame(frame).ok());
  frame.t_us = 1000;
  EXPECT_FALSE(slam.processFrame(frame).ok()) << "time going backwards";
}

TEST(VisualInertialSlam, OptionsLoadAndValidate) {
  auto cfg = ConfigNode::fromString(
      "filter: {type: nhinf, gamma: 5}\nmap: {k: 10}\nslam: {observation_passes: 10}", "a.yaml");
  VisualInertialSlamOptions o;
  ASSERT_TRUE(o.load(*cfg).ok());
  EXPECT_EQ(o.filter.type, FilterType::kNhinf);
  EXPECT_EQ(o.map.k, 10);
  EXPECT_EQ(o.slam.observation_passes, 10);
  EXPECT_FALSE(o.slam.second_order_mean);
  auto mean = ConfigNode::fromString("slam: {second_order_mean: true}", "a.yaml");
  VisualInertialSlamOptions m;
  ASSERT_TRUE(m.load(*mean).ok());
  EXPECT_TRUE(m.slam.second_order_mean);
  auto bad = ConfigNode::fromString("slam: {pixel_sigma: -1}", "a.yaml");
  EXPECT_FALSE(VisualInertialSlamOptions().load(*bad).ok());
  // A recorded IMU's accelerometer-bias prior is its own key, checked like the others.
  auto recorded = ConfigNode::fromString("slam: {recorded_accel_bias_sigma: 0.2}", "a.yaml");
  VisualInertialSlamOptions r;
  ASSERT_TRUE(r.load(*recorded).ok());
  EXPECT_DOUBLE_EQ(r.slam.recorded_accel_bias_sigma, 0.2);
  EXPECT_DOUBLE_EQ(r.slam.initial_accel_bias_sigma, SlamOptions().initial_accel_bias_sigma);
  auto zero = ConfigNode::fromString("slam: {recorded_accel_bias_sigma: 0}", "a.yaml");
  const Status s = VisualInertialSlamOptions().load(*zero);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("recorded_accel_bias_sigma"), std::string::npos) << s.message();
  // The shipped configuration loads with no unknown keys (with the image front end's
  // section, visual_slam_pipeline.h, and cooperation's, coop/dc_cooperation.h).
  auto shipped = test::shippedAgentConfig();
  ASSERT_TRUE(shipped.ok()) << shipped.status().message();
  ASSERT_TRUE(VisualInertialSlamOptions().load(*shipped).ok());
  ASSERT_TRUE(VisualFrontEndOptions().load(shipped->child("frontend")).ok());
  ASSERT_TRUE(coop::DcCooperationOptions().load(shipped->child("coop")).ok());
  // cvslam_agent's process section is transport's (AgentNodeOptions, cvslam_lcm_tests).
  shipped->skip("agent");
  EXPECT_TRUE(shipped->finish().ok()) << shipped->finish().message();
}

}  // namespace
}  // namespace cvslam
