// Image sensing end to end (cvslam_run --sensing images): map prediction for association
// (S = H P Hᵀ + R), the VisualSlamPipeline's input errors, and rendered sequences with fixed
// seeds judged by the renderer's ground truth: stereo-match and map-association precision,
// landmark truth, accuracy against INS-only dead reckoning, determinism.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "cvslam/io/config_node.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/rendered_sensing.h"
#include "cvslam/simrun/scenario_rendering.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/map_prediction.h"
#include "cvslam/slam/visual_slam_pipeline.h"
#include "shipped_config.h"

namespace cvslam {
namespace {

// A 25 m-radius circle at 10 m over the `aerial` world's building-free centre, 3 m/s, 10 Hz
// stereo with the thesis camera (320×240, α = 560, b = 0.2 m, looking down). The IMU has
// initial biases so that dead reckoning drifts by metres in 15 s.
/// perturb: the initial estimate sampled around the truth (the default of every scenario).
sim::Scenario imageScenario(double duration, uint64_t seed, bool perturb = true) {
  const std::string yaml =
      "name: test_images\nseed: " + std::to_string(seed) +
      "\nduration: " + std::to_string(duration) +
      "\nrender: {world: {kind: aerial, seed: 3}, options: {effects: {noise_sigma: 1.0}}}\n"
      "agents:\n"
      "  - id: 1\n"
      "    trajectory: {kind: circle, centre: [0.0, 0.0], radius: 25.0, altitude: 10.0, "
      "speed: 3.0, heading: velocity, tilt: bank}\n"
      "    imu: {accel_bias: [0.05, -0.04, 0.03], gyro_bias: [0.001, -0.001, 0.0005]}\n"
      "    camera_rate_hz: 10.0\n" +
      (perturb ? std::string() : std::string("    initial_uncertainty: {perturb: false}\n"));
  auto s = sim::Scenario::fromString(yaml, "test.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return *s;
}

struct ImageRun {
  RenderedSensingStats stats;
  double ate = 0.0, ins_ate = 0.0;
  int frames = 0, landmarks = 0, landmarks_with_truth = 0;
  double landmark_error_rms = 0.0;
  double pixel_sigma = 0.0;  ///< the pixel σ the filter assumed (frontend's override) [px]
  std::vector<Eigen::Vector3d> positions;
};

void runImages(const sim::Scenario& scenario, vision::DetectorType detector, ImageRun* result) {
  ImageRun& out = *result;
  // The shipped configuration (config/agent.yaml), detector as asked.
  VisualInertialSlamOptions options;
  VisualFrontEndOptions fe;
  auto cfg = test::shippedAgentConfig();
  ASSERT_TRUE(cfg.ok());
  ASSERT_TRUE(options.load(*cfg).ok());
  ASSERT_TRUE(fe.load(cfg->child("frontend")).ok()) << cfg->status().message();
  fe.front_end.detector.type = detector;
  auto rendering = chooseRenderWorld(scenario, "");
  ASSERT_TRUE(rendering.ok()) << rendering.status().message();
  auto factory = makeRenderedSensingFactory(*rendering, fe, nullptr);
  EXPECT_TRUE(factory.ok()) << factory.status().message();
  if (!factory.ok()) return;
  auto run = SimulatedTeamRun::create(scenario, options, *factory);
  EXPECT_TRUE(run.ok()) << run.status().message();
  if (!run.ok()) return;
  double se = 0.0, se_ins = 0.0;
  const Status s = (*run)->run([&](const SimulatedFrame& f) {
    const Eigen::Vector3d p = f.slam->vehicleState().head<3>();
    se += (p - f.truth->p_BinN).squaredNorm();
    se_ins += (f.x_ins->head<3>() - f.truth->p_BinN).squaredNorm();
    out.positions.push_back(p);
    ++out.frames;
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  out.ate = std::sqrt(se / std::max(out.frames, 1));
  out.ins_ate = std::sqrt(se_ins / std::max(out.frames, 1));
  ASSERT_EQ((*run)->agentCount(), 1u);
  const auto* rendered = dynamic_cast<const RenderedSensing*>(&(*run)->sensing(0));
  ASSERT_NE(rendered, nullptr);
  const RenderedSensing& sensing = *rendered;
  out.stats = sensing.stats();
  out.pixel_sigma = (*run)->slam(0).options().slam.pixel_sigma;
  double e2 = 0.0;
  for (const MapLandmark& m : (*run)->slam(0).map()) {
    ++out.landmarks;
    Eigen::Vector3d p_true;
    if (!sensing.landmarkTruth(m.id, &p_true)) continue;
    ++out.landmarks_with_truth;
    e2 += (m.p_LinN - p_true).squaredNorm();
  }
  out.landmark_error_rms = std::sqrt(e2 / std::max(out.landmarks_with_truth, 1));
  const RenderedSensingStats& st = out.stats;
  std::printf(
      "[ figures  ] %ld frames, %.0f obs/frame, stereo %.4f of %ld, association %.4f of %ld, "
      "ATE %.3f m, INS %.3f m, %d landmarks (%d with truth, rms %.3f m), per frame: front end "
      "%.1f ms, association %.2f ms, filter %.2f ms, render %.1f ms\n",
      st.frames, static_cast<double>(st.observations) / std::max(st.frames, 1L),
      st.stereoPrecision(), st.stereo_checked, st.associationPrecision(), st.associated_checked,
      out.ate, out.ins_ate, out.landmarks, out.landmarks_with_truth, out.landmark_error_rms,
      st.front_end_ms / std::max(st.frames, 1L), st.association_ms / std::max(st.frames, 1L),
      st.filter_ms / std::max(st.frames, 1L), st.render_ms / std::max(st.frames, 1L));
}

// Bound on the map's RMS error after the 15 s rendered circle from a perturbed start [m].
constexpr double kMaxLandmarkRms = 0.6;

void expectEndToEnd(const ImageRun& a) {
  ASSERT_EQ(a.frames, 151);
  const RenderedSensingStats& st = a.stats;
  EXPECT_GT(st.observations / st.frames, 100) << "too few stereo observations per frame";
  EXPECT_GT(st.stereo_checked, 10000);
  EXPECT_GE(st.stereoPrecision(), 0.98);
  EXPECT_GT(st.associated_checked, 2000) << "landmarks are hardly ever re-observed";
  EXPECT_GE(st.associationPrecision(), 0.97);
  // Every landmark of the map has its true point (the renderer saw a surface there).
  EXPECT_GT(a.landmarks, 100);
  EXPECT_EQ(a.landmarks_with_truth, a.landmarks);
  EXPECT_LT(a.landmark_error_rms, kMaxLandmarkRms);
  // … and no worse than the vehicle's own drift (no association errors in the map).
  EXPECT_LT(a.landmark_error_rms, 1.2 * a.ate);
  // Vision keeps the biased IMU in check: far better than dead reckoning.
  EXPECT_GT(a.ins_ate, 2.0);
  EXPECT_LT(a.ate, 0.05 * a.ins_ate) << "ATE " << a.ate << " m, INS-only " << a.ins_ate << " m";
}

TEST(ImageSlam, FastSiftEndToEndOnRenderedCircle) {
  // The shipped default: fast SIFT (§4.2.5 on our scale space), 150 matches described.
  ImageRun a;
  runImages(imageScenario(15.0, 11), vision::DetectorType::kFastSift, &a);
  // Measured with the bias estimates drawn from their prior (perturb_biases, the scenarios'
  // default): ATE 0.52 m, map 0.52 m (the reference below: 0.54 / 0.53 m); with exactly known
  // biases they were 0.36 / 0.37 and 0.30 / 0.30 m, under a bound of 0.45. On thesis_loop's
  // 210 s fast SIFT closes the loop that the reference misses (docs/front_end.md).
  expectEndToEnd(a);
  // The cap keeps what the association looks for: most observations near a prediction.
  EXPECT_LE(a.stats.observations, 150L * a.frames);
  // The assumed pixel σ is tighter than the simulator's but not below the keypoints' error
  // against the renderer's truth (measured 0.07-0.09 px; docs/front_end.md "Pixel σ").
  EXPECT_GE(a.pixel_sigma, a.stats.reobservationRms());
}

TEST(ImageSlam, AdaptiveSiftEndToEndOnRenderedCircle) {
  // The OpenCV-based reference: adaptive SIFT (§4.2.5). The bound is fast SIFT's (above): the
  // map's error is mostly the perturbed start's unobservable pose error (0.1 m, 1°: 0.35 m at
  // 20 m) and the drawn biases' tilt. Measured on seeds 11-16 with exactly known biases,
  // invariant chart: 0.40 / 0.49 / 0.51 / 0.79 / 0.15 / 0.28 m.
  ImageRun a;
  runImages(imageScenario(15.0, 11), vision::DetectorType::kAdaptiveSift, &a);
  expectEndToEnd(a);
}

TEST(ImageSlam, OrbPrecisionAndDeterminismOnRenderedCircle) {
  // Started at the truth: the ATE bound below asks whether vision holds the IMU's drift over
  // 8 s; the unobservable initial position and yaw error (0.1 m, 1°: 0.35 m at 20 m from the
  // start) would be most of an 8 s ATE. AdaptiveSiftEndToEnd runs from a perturbed start.
  const sim::Scenario scenario = imageScenario(8.0, 12, false);
  ImageRun a;
  runImages(scenario, vision::DetectorType::kOrb, &a);
  ASSERT_EQ(a.frames, 81);
  EXPECT_GT(a.stats.stereo_checked, 10000);
  EXPECT_GE(a.stats.stereoPrecision(), 0.98);
  EXPECT_GT(a.stats.associated_checked, 1000);
  EXPECT_GE(a.stats.associationPrecision(), 0.97);
  EXPECT_LT(a.ate, 0.25 * a.ins_ate) << "ATE " << a.ate << " m, INS-only " << a.ins_ate << " m";
  // Deterministic for a fixed seed.
  ImageRun b;
  runImages(scenario, vision::DetectorType::kOrb, &b);
  ASSERT_EQ(b.positions.size(), a.positions.size());
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    ASSERT_EQ(a.positions[i], b.positions[i]) << "frame " << i;
  }
  EXPECT_EQ(a.stats.associated, b.stats.associated);
}

// A filter with one landmark in the state and one archived, both in view.
class MapPredictionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    VisualInertialSlamOptions o;
    o.ins.estimate_imu_bias = false;
    o.map.k = 1;
    o.slam.reactivation_min_age_s = 0.0;
    slam_ = std::make_unique<VisualInertialSlam>(o, camera_);
    Eigen::VectorXd x0 = Eigen::VectorXd::Zero(9);
    x0.head<3>() = Eigen::Vector3d(0, 0, -10);
    const Eigen::MatrixXd P0 = Eigen::VectorXd::Constant(9, 0.01).asDiagonal();
    ASSERT_TRUE(slam_->initialize(0, x0, P0).ok());
  }
  StereoObservation observe(const Eigen::Vector3d& p_LinN, int64_t id, uint8_t d) const {
    StereoObservation obs;
    Eigen::Matrix<double, 9, 1> x = Eigen::Matrix<double, 9, 1>::Zero();
    x.head<3>() = Eigen::Vector3d(0, 0, -10);
    obs.z = camera_.project(x, p_LinN);
    obs.landmark_id = id;
    obs.descriptor.assign(32, d);
    return obs;
  }
  StereoCamera camera_{StereoCameraOptions()};
  std::unique_ptr<VisualInertialSlam> slam_;
};

TEST_F(MapPredictionTest, PredictsStateAndArchivedLandmarksWithCovariance) {
  const Eigen::Vector3d p1(0.5, 0.3, 0.0), p2(-0.5, -0.4, 0.2);
  StereoFrameObservations f;
  f.t_us = 0;
  f.observations = {observe(p1, 7, 1), observe(p2, 9, 2)};
  ASSERT_TRUE(slam_->processFrame(f).ok());
  // k = 1: the second frame sees only landmark 7, so landmark 9 goes to the archive.
  f.t_us = 100000;
  f.observations = {observe(p1, 7, 1)};
  ASSERT_TRUE(slam_->processFrame(f).ok());
  ASSERT_TRUE(slam_->archive().contains(9));

  std::vector<PredictedObservation> preds;
  MapPredictionOptions o;
  ASSERT_TRUE(slam_->propagateTo(100000).ok());
  ASSERT_TRUE(predictMapObservations(*slam_, o, &preds).ok());
  ASSERT_EQ(preds.size(), 2u);
  EXPECT_EQ(preds[0].landmark_id, 7);
  EXPECT_FALSE(preds[0].archived);
  EXPECT_EQ(preds[1].landmark_id, 9);
  EXPECT_TRUE(preds[1].archived);
  const Eigen::Matrix<double, 9, 1> x = slam_->vehicleState().head<9>();
  for (const PredictedObservation& p : preds) {
    ASSERT_NE(p.descriptor, nullptr);
    EXPECT_EQ(p.descriptor->size(), 32u);
    const Eigen::Vector3d p_L =
        p.archived
            ? slam_->archive().find(p.landmark_id)->p_LinN
            : Eigen::Vector3d(slam_->state().value(*slam_->state().find(VariableKey::landmark(7))));
    EXPECT_TRUE(p.z.isApprox(camera_.project(x, p_L), 1e-12));
    // S = H P Hᵀ + R: symmetric, and larger than R alone.
    EXPECT_TRUE(p.S.isApprox(p.S.transpose(), 1e-9));
    const Eigen::Matrix4d extra = p.S - 0.25 * Eigen::Matrix4d::Identity();
    EXPECT_GT(extra.ldlt().vectorD().minCoeff(), -1e-9);
    EXPECT_GT(extra.trace(), 1e-3);
  }
  // S of the state landmark against a direct H P Hᵀ + R with the joint covariance.
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  const StateVariable* lm = slam_->state().find(VariableKey::landmark(7));
  const StateVariable* veh = slam_->state().find(VariableKey::vehicle(0));
  camera_.project(x, slam_->state().value(*lm), &dz_dxv, &dz_dpL);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(4, slam_->state().size());
  H.block<4, 9>(0, veh->index) = dz_dxv;
  H.block<4, 3>(0, lm->index) = dz_dpL;
  const Eigen::MatrixXd S =
      H * slam_->state().covariance() * H.transpose() + 0.25 * Eigen::MatrixXd::Identity(4, 4);
  EXPECT_TRUE(preds[0].S.isApprox(S, 1e-9));

  // Without the archive only the state landmark; behind a far range nothing.
  o.include_archived = false;
  ASSERT_TRUE(slam_->propagateTo(100000).ok());
  ASSERT_TRUE(predictMapObservations(*slam_, o, &preds).ok());
  EXPECT_EQ(preds.size(), 1u);
  o.max_range_m = 1.0;
  ASSERT_TRUE(slam_->propagateTo(100000).ok());
  ASSERT_TRUE(predictMapObservations(*slam_, o, &preds).ok());
  EXPECT_TRUE(preds.empty());
}

// An archived landmark the filter would not re-activate yet (archived less than
// slam.reactivation_min_age_s ago) is not predicted: an association to it would be unused. A
// held one (slam.held_landmarks) is, at once: it comes back exactly at any age.
class MapPredictionArchive : public ::testing::TestWithParam<int> {};

TEST_P(MapPredictionArchive, SkipsArchivedLandmarksUntilTheyMayBeReactivated) {
  const StereoCamera camera{StereoCameraOptions()};
  VisualInertialSlamOptions o;
  o.ins.estimate_imu_bias = false;
  o.map.k = 1;
  o.slam.reactivation_min_age_s = 0.15;
  o.slam.held_landmarks = GetParam();
  const bool held = GetParam() > 0;
  VisualInertialSlam slam(o, camera);
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(9);
  x0.head<3>() = Eigen::Vector3d(0, 0, -10);
  ASSERT_TRUE(slam.initialize(0, x0, Eigen::VectorXd::Constant(9, 0.01).asDiagonal()).ok());
  auto observe = [&](const Eigen::Vector3d& p_LinN, int64_t id) {
    StereoObservation obs;
    obs.z = camera.project(x0.head<9>(), p_LinN);
    obs.landmark_id = id;
    obs.descriptor.assign(32, static_cast<uint8_t>(id));
    return obs;
  };
  const Eigen::Vector3d p1(0.5, 0.3, 0.0), p2(-0.5, -0.4, 0.2);
  StereoFrameObservations f;
  f.observations = {observe(p1, 7), observe(p2, 9)};
  ASSERT_TRUE(slam.processFrame(f).ok());
  f.t_us = 100000;
  f.observations = {observe(p1, 7)};
  ASSERT_TRUE(slam.processFrame(f).ok());
  ASSERT_TRUE(slam.archive().contains(9));
  const int64_t archived_us = slam.archive().find(9)->archived_us;
  for (int64_t t = 110000; t <= 400000; t += 10000) {
    ImuSample imu;
    imu.t_us = t;
    imu.accel_B = Eigen::Vector3d(0, 0, -9.81);
    ASSERT_TRUE(slam.addImu(imu).ok());
  }
  std::vector<PredictedObservation> preds;
  auto predictedIds = [&](int64_t t_us) {
    std::vector<int64_t> ids;
    EXPECT_TRUE(slam.propagateTo(t_us).ok());
    EXPECT_TRUE(predictMapObservations(slam, MapPredictionOptions(), &preds).ok());
    for (const PredictedObservation& p : preds) ids.push_back(p.landmark_id);
    return ids;
  };
  const int64_t t0 = std::max<int64_t>(archived_us, 100000);
  const std::vector<int64_t> both = {7, 9}, state_only = {7};
  EXPECT_EQ(predictedIds(t0), held ? both : state_only);
  EXPECT_EQ(predictedIds(archived_us + 140000), held ? both : state_only);
  EXPECT_EQ(predictedIds(archived_us + 160000), both);
  if (held) {  // with its correlation to the vehicle: the gate of a landmark in the state
    const PredictedObservation& p9 = preds[1];
    EXPECT_TRUE(p9.archived);
    const StateVariable* v9 = slam.state().find(VariableKey::heldLandmark(9));
    ASSERT_NE(v9, nullptr);
    EXPECT_FALSE(slam.state().covariance().block(0, v9->index, 9, 3).isZero());
  }
}

INSTANTIATE_TEST_SUITE_P(HeldOrNot, MapPredictionArchive, ::testing::Values(0, 20));

TEST_F(MapPredictionTest, Errors) {
  std::vector<PredictedObservation> preds;
  // Time going backwards.
  for (int64_t t = 5000; t <= 200000; t += 5000) {
    ImuSample imu;
    imu.t_us = t;
    imu.accel_B = Eigen::Vector3d(0, 0, -9.81);
    ASSERT_TRUE(slam_->addImu(imu).ok());
  }
  ASSERT_TRUE(slam_->propagateTo(200000).ok());
  EXPECT_FALSE(slam_->propagateTo(100000).ok());
  // An uninitialised filter.
  VisualInertialSlam fresh(VisualInertialSlamOptions(), camera_);
  EXPECT_FALSE(predictMapObservations(fresh, {}, &preds).ok());
}

TEST(VisualSlamPipeline, RejectsBadImagesAndOptions) {
  const StereoCamera camera{StereoCameraOptions()};
  VisualFrontEndOptions o;
  auto pipeline = VisualSlamPipeline::create(o, camera, nullptr);
  ASSERT_TRUE(pipeline.ok()) << pipeline.status().message();
  VisualInertialSlamOptions so;
  VisualInertialSlam slam(so, camera);
  const int n = vehicle::size(so.ins.estimate_imu_bias);
  ASSERT_TRUE(
      slam.initialize(0, Eigen::VectorXd::Zero(n), Eigen::MatrixXd::Identity(n, n) * 0.01).ok());
  VisualFrameResult r;
  const cv::Mat good(240, 320, CV_8UC1, cv::Scalar(100));
  EXPECT_FALSE(pipeline->process(0, cv::Mat(), good, slam, &r).ok());
  EXPECT_FALSE(pipeline->process(0, cv::Mat(240, 320, CV_8UC3), good, slam, &r).ok());
  EXPECT_FALSE(pipeline
                   ->process(0, cv::Mat(120, 160, CV_8UC1, cv::Scalar(1)),
                             cv::Mat(120, 160, CV_8UC1, cv::Scalar(1)), slam, &r)
                   .ok());
  // A blank pair is fine: no observations, the filter just propagates.
  EXPECT_TRUE(pipeline->process(100000, good, good, slam, &r).ok());
  EXPECT_TRUE(r.frame.observations.empty());
  EXPECT_EQ(r.report.observations, 0);
  // Uninitialised filter: the error of the filter comes back.
  VisualInertialSlam fresh(so, camera);
  EXPECT_FALSE(pipeline->process(0, good, good, fresh, &r).ok());
  // A vocabulary of the wrong descriptor type is refused.
  o.front_end.detector.type = vision::DetectorType::kOrb;
  cv::Mat desc(64, 128, CV_8U);
  cv::randu(desc, 0, 255);
  vision::VocabularyOptions vo;
  vo.branching = 4;
  vo.depth = 1;
  auto vocab = vision::Vocabulary::train(desc, vision::DescriptorType::kSift, vo);
  ASSERT_TRUE(vocab.ok()) << vocab.status().message();
  EXPECT_FALSE(VisualSlamPipeline::create(
                   o, camera, std::make_shared<const vision::Vocabulary>(std::move(*vocab)))
                   .ok());
}

// The front end's overrides of slam options reach the filter it feeds, on the first frame.
TEST(VisualSlamPipeline, OverridesReachTheFilter) {
  const StereoCamera camera{StereoCameraOptions()};
  VisualInertialSlamOptions so;
  so.slam.pixel_sigma = 0.5;
  so.slam.second_order_noise = true;
  VisualFrontEndOptions o;
  o.pixel_sigma = 0.2;
  o.second_order_noise = false;
  auto pipeline = VisualSlamPipeline::create(o, camera, nullptr);
  ASSERT_TRUE(pipeline.ok()) << pipeline.status().message();
  VisualInertialSlam slam(so, camera);
  const int n = vehicle::size(so.ins.estimate_imu_bias);
  ASSERT_TRUE(
      slam.initialize(0, Eigen::VectorXd::Zero(n), Eigen::MatrixXd::Identity(n, n) * 0.01).ok());
  const cv::Mat blank(240, 320, CV_8UC1, cv::Scalar(100));
  VisualFrameResult r;
  ASSERT_TRUE(pipeline->process(100000, blank, blank, slam, &r).ok());
  EXPECT_EQ(slam.options().slam.pixel_sigma, 0.2);
  EXPECT_FALSE(slam.options().slam.second_order_noise);
}

TEST(ImageSlam, ScenarioRenderSectionErrors) {
  const std::string agents =
      "agents:\n  - id: 1\n    trajectory: {kind: circle, radius: 25.0, altitude: 10.0, "
      "speed: 3.0}\n";
  // The scenario keeps the section as text (it loads without the renderer); every program that
  // renders parses it, and refuses what does not parse, naming the file.
  auto rendering = [&](const std::string& section) -> Expected<ScenarioRendering> {
    auto scenario = sim::Scenario::fromString(section + agents, "t.yaml");
    if (!scenario.ok()) return scenario.status();
    return ScenarioRendering::parse(*scenario);
  };
  auto moon = rendering("render: {world: {kind: moon}}\n");
  ASSERT_FALSE(moon.ok());
  EXPECT_NE(moon.status().message().find("t.yaml"), std::string::npos) << moon.status().message();
  EXPECT_NE(moon.status().message().find("moon"), std::string::npos) << moon.status().message();
  EXPECT_FALSE(rendering("render: {wrld: {}}\n").ok());
  EXPECT_FALSE(rendering("render: {options: {far: -1}}\n").ok());
  EXPECT_FALSE(sim::Scenario::fromString("render: 3\n" + agents, "t.yaml").ok());
  auto hall = rendering("render: {world: {kind: hall}}\n");
  ASSERT_TRUE(hall.ok()) << hall.status().message();
  ASSERT_TRUE(hall->world.has_value());
  EXPECT_EQ(hall->world->kind, render::WorldKind::kHall);
  auto none = rendering("");
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->world.has_value());
}

TEST(ImageSlam, ShippedFrontendConfigLoads) {
  auto cfg = test::shippedAgentConfig();
  ASSERT_TRUE(cfg.ok());
  VisualFrontEndOptions o;
  EXPECT_TRUE(o.load(cfg->child("frontend")).ok()) << cfg->status().message();
  EXPECT_EQ(o.front_end.detector.type, vision::DetectorType::kFastSift);
  EXPECT_EQ(o.front_end.detector.fast_sift.describe_budget, 150);
  EXPECT_TRUE(o.loop_detection.enabled);
  EXPECT_EQ(o.loop_detection.min_inliers, 6);
  EXPECT_EQ(o.tracked_landmarks, 0);
  EXPECT_EQ(o.new_landmark_order, NewLandmarkOrder::kConfirmation);
  EXPECT_EQ(o.new_landmark_grid, 4);
  for (const char* text : {"confirm_gate_px: -1\n", "pixel_sigma: 0\n", "tracked_landmarks: -2\n",
                           "new_landmark_order: strongest\n", "new_landmark_grid: 0\n",
                           "loop_detection: {min_inliers: 1}\n", "loop_detection: {typo: 1}\n"}) {
    auto bad = ConfigNode::fromString(text, "bad.yaml");
    ASSERT_TRUE(bad.ok());
    VisualFrontEndOptions b;
    b.load(*bad);
    EXPECT_FALSE(bad->finish().ok()) << text;
  }
}

// Each detector gets the vocabulary of its own descriptor type from the shipped config; a
// vocabulary of the other type is an error, not a silent feature index 0.
TEST(ImageSlam, ShippedVocabulariesFitTheirDetectors) {
  const std::string config_dir = std::string(CVSLAM_SOURCE_DIR) + "/config";
  auto cfg = test::shippedAgentConfig();
  ASSERT_TRUE(cfg.ok());
  VisualFrontEndOptions o;
  ASSERT_TRUE(o.load(cfg->child("frontend")).ok());
  for (auto type : {vision::DetectorType::kAdaptiveSift, vision::DetectorType::kOrb}) {
    o.front_end.detector.type = type;
    auto v = loadFeatureIndexVocabulary(o, config_dir);
    ASSERT_TRUE(v.ok()) << v.status().message();
    ASSERT_TRUE(*v);
    EXPECT_EQ((*v)->type(), type == vision::DetectorType::kOrb ? vision::DescriptorType::kOrb
                                                               : vision::DescriptorType::kSift);
  }
  std::swap(o.vocabulary, o.vocabulary_orb);  // ORB detector, SIFT vocabulary
  auto wrong = loadFeatureIndexVocabulary(o, config_dir);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.status().message().find("does not fit"), std::string::npos);
  o.vocabulary_orb = "missing.cvoc";
  EXPECT_FALSE(loadFeatureIndexVocabulary(o, config_dir).ok());
  o.vocabulary_orb.clear();
  auto none = loadFeatureIndexVocabulary(o, config_dir);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(*none);
}

}  // namespace
}  // namespace cvslam
