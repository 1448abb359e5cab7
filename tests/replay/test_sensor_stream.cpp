// SensorStreamSource pieces: simulated per-agent streams, the merge on the shared play clock,
// the play window, EuRoC folders on one clock, and the render-world choice.

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "cvslam/dataset/euroc_dataset_writer.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/sensors/euroc_sensor_stream.h"
#include "cvslam/sensors/merged_sensor_source.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/simrun/scenario_rendering.h"
#include "cvslam/simrun/simulated_sensor_stream.h"
#include "euroc_test_folder.h"
#include "small_scenario.h"
#include "test_paths.h"

namespace cvslam {
namespace {

sim::Scenario smallScenario(double duration) {
  auto s = sim::Scenario::fromString(test::smallScenarioYaml(duration, false), "small");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return *s;
}

TEST(SensorStream, SimulatedFeatureTeamIsMergedInOrder) {
  SimulatedSensorOptions o;
  o.render = false;
  auto team = simulateTeam(smallScenario(2.0), o);
  ASSERT_TRUE(team.ok()) << team.status().message();
  auto sim = team->simulator;
  MergedSensorSource source(std::move(team->streams));
  SensorEvent e, prev;
  bool first = true;
  std::map<std::pair<int, SensorEventType>, int> counts;
  while (source.next(e)) {
    if (!first) {
      EXPECT_FALSE(
          eventBefore(e.play_us, e.type, e.agent_id, prev.play_us, prev.type, prev.agent_id))
          << "event out of order at " << e.play_us;
    }
    EXPECT_EQ(e.t_us, e.play_us);  // simulations start at 0
    if (e.type == SensorEventType::kGroundTruth) {
      const sim::GroundTruth truth = sim->agentById(e.agent_id)->truth(e.t_us);
      EXPECT_LT((e.truth.p_BinN - truth.p_BinN).norm(), 1e-12);
      EXPECT_LT((e.truth.q_BtoN.toRotationMatrix() - rotationBodyToNav<double>(truth.euler)).norm(),
                1e-12);
      EXPECT_LT((e.truth.v_N - truth.v_N).norm(), 1e-12);
    }
    if (e.type == SensorEventType::kFeatures) {
      EXPECT_FALSE(e.features.observations.empty());
    }
    ++counts[{e.agent_id, e.type}];
    prev = e;
    first = false;
  }
  ASSERT_TRUE(source.status().ok());
  for (int id : {1, 2}) {
    EXPECT_EQ((counts[{id, SensorEventType::kImu}]), 401);  // 0..2 s at 200 Hz, inclusive
    EXPECT_EQ((counts[{id, SensorEventType::kGroundTruth}]), 401);
    EXPECT_EQ((counts[{id, SensorEventType::kFeatures}]), 21);
    EXPECT_EQ((counts[{id, SensorEventType::kStereoImage}]), 0);
  }
}

TEST(SensorStream, PlayWindowCutsStartAndDuration) {
  SimulatedSensorOptions o;
  o.render = false;
  o.start = 0.5;
  auto team = simulateTeam(smallScenario(2.0), o);
  ASSERT_TRUE(team.ok());
  MergedSensorSource source(std::move(team->streams), PlayWindow{0.5, 0.5});
  SensorEvent e;
  int n = 0;
  int64_t lo = INT64_MAX, hi = INT64_MIN;
  while (source.next(e)) {
    lo = std::min(lo, e.play_us);
    hi = std::max(hi, e.play_us);
    ++n;
  }
  EXPECT_EQ(lo, 500000);
  EXPECT_EQ(hi, 1000000);
  EXPECT_EQ(n, 2 * (101 + 101 + 6));  // per agent: IMU, ground truth, frames in [0.5, 1.0]
}

TEST(SensorStream, RenderedFramesAreTexturedMono8) {
  SimulatedSensorOptions o;
  auto team = simulateTeam(smallScenario(0.3), o);
  ASSERT_TRUE(team.ok()) << team.status().message();
  MergedSensorSource source(std::move(team->streams));
  SensorEvent e;
  int frames = 0;
  while (source.next(e)) {
    if (e.type != SensorEventType::kStereoImage) continue;
    ++frames;
    ASSERT_EQ(e.left.type(), CV_8UC1);
    EXPECT_EQ(e.left.cols, 320);
    EXPECT_EQ(e.left.rows, 240);
    EXPECT_EQ(e.right.size(), e.left.size());
    cv::Scalar mean, stddev;
    cv::meanStdDev(e.left, mean, stddev);
    EXPECT_GT(stddev[0], 5.0) << "rendered image has no texture";
    EXPECT_GT(cv::norm(e.left, e.right, cv::NORM_L1), 0.0) << "left and right identical";
  }
  EXPECT_EQ(frames, 2 * 4);
}

// Two EuRoC folders recorded at different times play on one clock (each from its start).
TEST(SensorStream, EurocFoldersShareOneClock) {
  test::TempFolder tmp;
  const int64_t starts_us[2] = {1'000'000'000, 5'000'000'000};
  for (int k = 0; k < 2; ++k) {
    EurocWriterOptions wo;
    auto w = EurocDatasetWriter::create(tmp / ("d" + std::to_string(k)), wo);
    ASSERT_TRUE(w.ok()) << w.status().message();
    cv::Mat img(wo.camera.height, wo.camera.width, CV_8UC1, cv::Scalar(40 + k));
    for (int i = 0; i <= 20; ++i) {
      ImuSample s;
      s.t_us = starts_us[k] + i * 5000;
      s.accel_B.z() = -9.81 + k;
      ASSERT_TRUE(w->addImu(s).ok());
      if (i % 10 == 0) {
        ASSERT_TRUE(w->addStereoFrame(s.t_us * 1000, img, img).ok());
      }
    }
    ASSERT_TRUE(w->close().ok());
  }
  std::vector<std::unique_ptr<AgentSensorStream>> streams;
  for (int k = 0; k < 2; ++k) {
    auto s = EurocSensorStream::open(k + 1, tmp / ("d" + std::to_string(k)));
    ASSERT_TRUE(s.ok()) << s.status().message();
    EXPECT_EQ((*s)->offsetUs(), starts_us[k]);
    streams.push_back(std::move(*s));
  }
  MergedSensorSource source(std::move(streams));
  SensorEvent e;
  std::vector<std::pair<int64_t, int>> order;
  while (source.next(e)) {
    EXPECT_EQ(e.t_us, e.play_us + starts_us[e.agent_id - 1]);
    if (e.type == SensorEventType::kStereoImage) {
      EXPECT_EQ(e.left.at<uint8_t>(0, 0), 40 + e.agent_id - 1);
    }
    order.emplace_back(e.play_us, e.agent_id);
  }
  ASSERT_TRUE(source.status().ok()) << source.status().message();
  ASSERT_EQ(order.size(), 2u * (21 + 3));
  // Interleaved: both agents at play time 0 first, agent 1 before agent 2.
  EXPECT_EQ(order[0], std::make_pair(int64_t{0}, 1));
  EXPECT_EQ(order[1], std::make_pair(int64_t{0}, 2));
  EXPECT_EQ(order.back().first, 100000);
}

TEST(SensorStream, EurocStreamCorrectsAConstantCameraClockOffset) {
  // Frames stamped on the camera's clock, 3 ms behind the IMU's: with the offset given, each
  // frame is handed out at its IMU time, after the IMU sample that precedes it there.
  test::TempFolder tmp;
  EurocWriterOptions wo;
  auto w = EurocDatasetWriter::create(tmp / "d", wo);
  ASSERT_TRUE(w.ok());
  cv::Mat img(wo.camera.height, wo.camera.width, CV_8UC1, cv::Scalar(1));
  for (int i = 0; i <= 20; ++i) {
    ImuSample s;
    s.t_us = 1000000 + i * 5000;
    ASSERT_TRUE(w->addImu(s).ok());
    if (i % 10 == 0) {
      ASSERT_TRUE(w->addStereoFrame(s.t_us * 1000, img, img).ok());
    }
  }
  ASSERT_TRUE(w->close().ok());
  auto s = EurocSensorStream::open(1, tmp / "d", 0.0, 3000);
  ASSERT_TRUE(s.ok()) << s.status().message();
  SensorEvent e;
  std::vector<int64_t> frames;
  int64_t last_imu = -1;
  while ((*s)->next(e)) {
    if (e.type == SensorEventType::kImu) last_imu = e.t_us;
    if (e.type != SensorEventType::kStereoImage) continue;
    frames.push_back(e.t_us);
    EXPECT_EQ(last_imu, e.t_us - 3000);  // the tick before it, not the one it was stamped on
  }
  ASSERT_TRUE((*s)->status().ok()) << (*s)->status().message();
  EXPECT_EQ(frames, (std::vector<int64_t>{1003000, 1053000, 1103000}));
}

TEST(SensorStream, EurocStreamReportsBrokenImages) {
  test::TempFolder tmp;
  EurocWriterOptions wo;
  auto w = EurocDatasetWriter::create(tmp / "d", wo);
  ASSERT_TRUE(w.ok());
  cv::Mat img(wo.camera.height, wo.camera.width, CV_8UC1, cv::Scalar(1));
  ASSERT_TRUE(w->addStereoFrame(1000, img, img).ok());
  ASSERT_TRUE(w->addImu(ImuSample{}).ok());  // a folder needs IMU from its first frame on
  ASSERT_TRUE(w->close().ok());
  auto s = EurocSensorStream::open(1, tmp / "d");
  ASSERT_TRUE(s.ok()) << s.status().message();
  // Truncate the left PNG after open() checked its header: decoding must fail cleanly.
  std::ofstream(tmp / "d/mav0/cam0/data/1000.png", std::ios::binary | std::ios::trunc)
      << "\x89PNG\r\n\x1a\n";
  SensorEvent e;
  int events = 0;
  while ((*s)->next(e)) ++events;
  EXPECT_EQ(events, 1);  // the IMU sample; the frame is not delivered
  EXPECT_FALSE((*s)->status().ok());
  EXPECT_NE((*s)->status().message().find("1000.png"), std::string::npos)
      << (*s)->status().message();
}

TEST(RenderWorldChoice, OutdoorScenariosGoAerialTumScenariosGoToTheHall) {
  auto aerial = chooseRenderWorld(smallScenario(1.0), "");
  ASSERT_TRUE(aerial.ok());
  EXPECT_EQ(aerial->options.kind, render::WorldKind::kAerial);
  EXPECT_NE(aerial->reason.find("outdoor"), std::string::npos);
  auto hall = sim::Scenario::loadFile(test::sourceDir() + "/config/scenarios/euroc_mh03_hall.yaml");
  ASSERT_TRUE(hall.ok()) << hall.status().message();
  auto choice = chooseRenderWorld(*hall, "");
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->options.kind, render::WorldKind::kHall);
  EXPECT_EQ(choice->options.seed, render::WorldOptions().seed);  // one world for every seed
  auto forced = chooseRenderWorld(*hall, "aerial");
  ASSERT_TRUE(forced.ok());
  EXPECT_EQ(forced->options.kind, render::WorldKind::kAerial);
  auto bad = chooseRenderWorld(*hall, "moon");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("moon"), std::string::npos);
}

TEST(RenderWorldChoice, TheScenariosOwnRenderWorldIsHonoured) {
  // euroc_recorded_mh.yaml gives `render: world: {kind: hall, seed: 2102}`.
  auto mh = sim::Scenario::loadFile(test::sourceDir() + "/config/scenarios/euroc_recorded_mh.yaml");
  ASSERT_TRUE(mh.ok()) << mh.status().message();
  auto rendering = ScenarioRendering::parse(*mh);
  ASSERT_TRUE(rendering.ok() && rendering->world.has_value());
  const uint64_t seed = rendering->world->seed;
  ASSERT_NE(seed, render::WorldOptions().seed);
  auto choice = chooseRenderWorld(*mh, "");
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->options.kind, render::WorldKind::kHall);
  EXPECT_EQ(choice->options.seed, seed);
  EXPECT_NE(choice->reason.find("scenario"), std::string::npos) << choice->reason;
  // A request changes the kind and keeps the rest of the scenario's world.
  auto aerial = chooseRenderWorld(*mh, "aerial");
  ASSERT_TRUE(aerial.ok());
  EXPECT_EQ(aerial->options.kind, render::WorldKind::kAerial);
  EXPECT_EQ(aerial->options.seed, seed);
}

}  // namespace
}  // namespace cvslam
