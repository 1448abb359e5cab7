// AgentPipeline (the agent process's core) against SimulatedTeamRun (cvslam_run's core): fed
// the same simulator events one by one, it must end in exactly the same state; and the
// calibration an agent process reads (scenario or EuRoC folder) starts it the same way.
#include <gtest/gtest.h>

#include "cvslam/dataset/euroc_sensor_yaml.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/json_file.h"
#include "cvslam/io/run_reader.h"
#include "cvslam/scenario_setup/scenario_calibration.h"
#include "cvslam/sensors/sensor_event_orderer.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/agent_calibration.h"
#include "cvslam/slam/agent_pipeline.h"
#include "cvslam/slam/agent_run_recorder.h"
#include "euroc_test_folder.h"
#include "replay/small_scenario.h"

namespace cvslam {
namespace {

sim::Scenario smallScenario(double duration) {
  auto s = sim::Scenario::fromString(test::smallScenarioYaml(duration, true), "small.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return *s;
}

TEST(AgentPipeline, FeatureLevelEqualsSimulatedTeamRun) {
  const sim::Scenario scenario = smallScenario(8.0);
  VisualInertialSlamOptions options;
  options.ins.estimate_imu_bias = true;
  auto team = SimulatedTeamRun::create(scenario, options);
  ASSERT_TRUE(team.ok()) << team.status().message();
  ASSERT_TRUE((*team)->run(nullptr).ok());

  // The agent process's path: calibration from the scenario, then message by message.
  for (int id : {1, 2}) {
    auto calibration = calibrationFromScenario(scenario, id, options);
    ASSERT_TRUE(calibration.ok()) << calibration.status().message();
    auto agent = AgentPipeline::create(id, *calibration->setup, calibration->camera);
    ASSERT_TRUE(agent.ok());
    auto sim = sim::Simulator::create(scenario);
    ASSERT_TRUE(sim.ok());
    sim::SimEvent ev;
    while (sim->next(ev)) {
      if (ev.agent_id != id) continue;
      if (ev.type == SensorEventType::kImu) {
        ASSERT_TRUE((*agent)->addImu(ev.imu).ok());
      } else {
        ASSERT_TRUE((*agent)->processFeatures(ev.frame).ok());
        EXPECT_EQ((*agent)->lastFrame().t_us, ev.t_us);
        ASSERT_NE((*agent)->lastFrame().observations, nullptr);
      }
    }
    const std::size_t slot = id == 1 ? 0 : 1;
    ASSERT_EQ((*team)->agentId(slot), id);
    const VisualInertialSlam& expected = (*team)->slam(slot);
    const VisualInertialSlam& got = (*agent)->slam();
    EXPECT_GT((*agent)->frames(), 70);
    EXPECT_EQ(got.state().size(), expected.state().size());
    EXPECT_EQ(got.vehicleState(), expected.vehicleState()) << "agent " << id;
    EXPECT_EQ(got.vehicleCovariance(), expected.vehicleCovariance()) << "agent " << id;
    EXPECT_EQ(got.map().size(), expected.map().size());
    EXPECT_EQ((*agent)->insState(), (*team)->pipeline(slot).insState());
  }
}

TEST(AgentPipeline, ErrorsNameTheAgentAndImagesNeedAPipeline) {
  const sim::Scenario scenario = smallScenario(2.0);
  auto calibration = calibrationFromScenario(scenario, 2, VisualInertialSlamOptions());
  ASSERT_TRUE(calibration.ok());
  auto agent = AgentPipeline::create(2, *calibration->setup, calibration->camera);
  ASSERT_TRUE(agent.ok());
  cv::Mat img(240, 320, CV_8UC1, cv::Scalar(0));
  Status s = (*agent)->processImages(0, img, img);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("agent 2"), std::string::npos) << s.message();
  EXPECT_FALSE(calibrationFromScenario(scenario, 7, VisualInertialSlamOptions()).ok());
}

TEST(AgentCalibration, EurocFolderGivesTheRectifiedCameraAndImuNoise) {
  test::TempFolder dir;
  const std::string mav0 = dir / "mav0";
  std::filesystem::create_directories(mav0 + "/cam0");
  std::filesystem::create_directories(mav0 + "/cam1");
  std::filesystem::create_directories(mav0 + "/imu0");
  EurocCameraInfo cam;
  cam.width = 320;
  cam.height = 240;
  cam.intrinsics << 400, 400, 160, 120;
  // Camera looking down (x_C right wing, y_C tail), as StereoCameraOptions' default.
  cam.T_BS.topLeftCorner<3, 3>() = StereoCameraOptions().R_BtoC.transpose();
  cam.T_BS.topRightCorner<3, 1>() << 0.1, 0.0, 0.05;
  std::ofstream(mav0 + "/cam0/sensor.yaml") << formatEurocCameraYaml(cam);
  EurocCameraInfo right = cam;
  // Right camera 0.25 m along +x_C of the left one.
  right.T_BS.topRightCorner<3, 1>() += cam.T_BS.topLeftCorner<3, 3>() * Eigen::Vector3d(0.25, 0, 0);
  std::ofstream(mav0 + "/cam1/sensor.yaml") << formatEurocCameraYaml(right);
  EurocImuInfo imu;
  imu.gyroscope_noise_density = 3e-4;
  imu.accelerometer_random_walk = 4e-3;
  std::ofstream(mav0 + "/imu0/sensor.yaml") << formatEurocImuYaml(imu);

  auto c = calibrationFromEuroc(dir.path(), VisualInertialSlamOptions());
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_FALSE(c->setup.has_value());      // starts at the first ground truth
  EXPECT_FALSE(c->rectifier.has_value());  // already a rectified pair
  const StereoCameraOptions& o = c->camera.options();
  EXPECT_DOUBLE_EQ(o.fx, 400.0);
  EXPECT_NEAR(o.baseline, 0.25, 1e-12);
  EXPECT_TRUE(o.R_BtoC.isApprox(StereoCameraOptions().R_BtoC, 1e-12));
  EXPECT_TRUE(o.p_CinB.isApprox(Eigen::Vector3d(0.1, 0.0, 0.05), 1e-12));
  EXPECT_DOUBLE_EQ(c->options.ins.gyro_noise_density, 3e-4);
  EXPECT_DOUBLE_EQ(c->options.ins.accel_random_walk, 4e-3);
  // A sensor.yaml is a datasheet: its random walks keep the datasheet factor.
  EXPECT_DOUBLE_EQ(c->options.ins.datasheet_random_walk_scale,
                   InsPropagatorOptions().datasheet_random_walk_scale);
  // A recording's turn-on accelerometer bias is unknown: the recorded IMU's prior σ.
  EXPECT_DOUBLE_EQ(c->options.slam.initial_accel_bias_sigma,
                   SlamOptions().recorded_accel_bias_sigma);

  // An IMU mounted x-up with a lever arm (as the EuRoC VI-sensor's): the body frame is the
  // IMU frame, the cameras are re-expressed relative to it.
  EurocImuInfo mounted = imu;
  const Eigen::Matrix3d R_ItoB =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d p_IinB(0.02, -0.01, 0.03);
  mounted.T_BS.topLeftCorner<3, 3>() = R_ItoB;
  mounted.T_BS.topRightCorner<3, 1>() = p_IinB;
  std::ofstream(mav0 + "/imu0/sensor.yaml") << formatEurocImuYaml(mounted);
  auto m = calibrationFromEuroc(dir.path(), VisualInertialSlamOptions());
  ASSERT_TRUE(m.ok()) << m.status().message();
  const StereoCameraOptions& mo = m->camera.options();
  EXPECT_TRUE(mo.R_BtoC.isApprox(StereoCameraOptions().R_BtoC * R_ItoB, 1e-12));
  EXPECT_TRUE(
      mo.p_CinB.isApprox(R_ItoB.transpose() * (Eigen::Vector3d(0.1, 0.0, 0.05) - p_IinB), 1e-12));
  EXPECT_NEAR(mo.baseline, 0.25, 1e-12);
  std::ofstream(mav0 + "/imu0/sensor.yaml") << formatEurocImuYaml(imu);

  // Distorted cameras need the rectifier; its model has the rectified focal length.
  cam.distortion = {-0.28, 0.07, 0.0002, 0.00002};
  right.distortion = cam.distortion;
  std::ofstream(mav0 + "/cam0/sensor.yaml") << formatEurocCameraYaml(cam);
  std::ofstream(mav0 + "/cam1/sensor.yaml") << formatEurocCameraYaml(right);
  auto d = calibrationFromEuroc(mav0, VisualInertialSlamOptions());
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_TRUE(d->rectifier.has_value());
  EXPECT_NEAR(d->camera.options().baseline, 0.25, 1e-9);
  EXPECT_GT(d->camera.options().fx, 100.0);

  EXPECT_FALSE(calibrationFromEuroc(dir / "nothing", VisualInertialSlamOptions()).ok());
}

TEST(AgentSetup, KnownPoseStartsAtTheGroundTruth) {
  VisualInertialSlamOptions options;
  options.ins.estimate_imu_bias = true;
  InitialUncertainty sigma;
  const Eigen::Vector3d euler(0.0, 0.0, M_PI / 2);  // heading east
  const AgentFilterSetup s =
      knownPoseSetup(5, Eigen::Vector3d(1, 2, -3), Eigen::Vector3d(0, 2, 0), euler, sigma, options);
  ASSERT_EQ(s.x0.size(), 15);
  EXPECT_EQ(s.t0_us, 5);
  EXPECT_TRUE(s.x0.head<3>().isApprox(Eigen::Vector3d(1, 2, -3)));
  EXPECT_TRUE(s.x0.segment<3>(3).isApprox(Eigen::Vector3d(2, 0, 0), 1e-12));  // forward
  EXPECT_DOUBLE_EQ(s.P0(0, 0), 0.01);
  EXPECT_DOUBLE_EQ(s.P0(9, 9),
                   options.slam.initial_accel_bias_sigma * options.slam.initial_accel_bias_sigma);
  EXPECT_TRUE(s.x0.tail<6>().isZero());
  // A real IMU's turn-on bias (slam.initial_*_bias) starts the bias states.
  auto cfg = ConfigNode::fromString(
      "slam: {initial_gyro_bias: [0.077, 0.021, 0.003], initial_accel_bias: [0.1, 0, 0]}\n",
      "bias.yaml");
  ASSERT_TRUE(cfg.ok());
  ASSERT_TRUE(options.load(*cfg).ok());
  const AgentFilterSetup b =
      knownPoseSetup(5, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), euler, sigma, options);
  EXPECT_TRUE(b.x0.segment<3>(12).isApprox(Eigen::Vector3d(0.077, 0.021, 0.003)));
  EXPECT_DOUBLE_EQ(b.x0(9), 0.1);
  auto bad = ConfigNode::fromString("slam: {initial_gyro_bias: [0, .nan, 0]}\n", "bad.yaml");
  ASSERT_TRUE(bad.ok());
  EXPECT_FALSE(VisualInertialSlamOptions().load(*bad).ok());
}

TEST(AgentRunRecorder, RecordReadableWhileRunningAndAfter) {
  test::TempFolder dir;
  const sim::Scenario scenario = smallScenario(3.0);
  auto calibration = calibrationFromScenario(scenario, 1, VisualInertialSlamOptions());
  ASSERT_TRUE(calibration.ok());
  auto agent = AgentPipeline::create(1, *calibration->setup, calibration->camera);
  ASSERT_TRUE(agent.ok());
  AgentRunRecorder recorder;
  ASSERT_TRUE(recorder.open(dir.path(), 1, false).ok());
  auto sim = sim::Simulator::create(scenario);
  ASSERT_TRUE(sim.ok());
  sim::SimEvent ev;
  int frames = 0;
  while (sim->next(ev)) {
    if (ev.agent_id != 1) continue;
    if (ev.type == SensorEventType::kImu) {
      ASSERT_TRUE((*agent)->addImu(ev.imu).ok());
      continue;
    }
    ASSERT_TRUE((*agent)->processFeatures(ev.frame).ok());
    Vector9d truth;
    truth << ev.truth.p_BinN, ev.truth.v_B, ev.truth.euler;
    ASSERT_TRUE(recorder.addFrame(**agent, &truth, 2.5).ok());
    if (++frames == 10) {
      // Periodic output: a reader sees the first ten frames while the run goes on.
      recorder.writer().setBytesSent("SUMMARY", 1000);
      ASSERT_TRUE(recorder.flush().ok());
      auto run = readAgentRun(dir.path(), 1);
      ASSERT_TRUE(run.ok()) << run.status().message();
      EXPECT_EQ(run->trajectory.size(), 10u);
      EXPECT_EQ(run->stats.frames.size(), 10u);
    }
  }
  ASSERT_TRUE(calibration->landmark_truth);
  ASSERT_TRUE(recorder.writeMap((*agent)->slam(), calibration->landmark_truth).ok());
  ASSERT_TRUE(recorder.close().ok());
  auto run = readAgentRun(dir.path(), 1);
  ASSERT_TRUE(run.ok());
  EXPECT_EQ(run->trajectory.size(), 31u);
  EXPECT_EQ(run->truth.size(), 31u);
  ASSERT_TRUE(run->ins_trajectory.has_value());
  EXPECT_FALSE(run->landmarks.empty());
  EXPECT_TRUE(run->landmarks.front().truth.has_value());
  EXPECT_TRUE(std::filesystem::exists(dir / "agent_1/events.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "agent_1/frontend.csv"));  // no image frame
  auto stats = readJsonFile(dir / "agent_1/stats.json");
  ASSERT_TRUE(stats.ok());
  EXPECT_DOUBLE_EQ(stats->at("frames").at("latency_ms").at(0).get<double>(), 2.5);
  EXPECT_NEAR(stats->at("bytes_sent_per_s").at("SUMMARY").get<double>(), 1000.0 / 3.0, 1e-9);
}

SensorEvent event(SensorEventType type, int64_t t_us) {
  SensorEvent e;
  e.type = type;
  e.t_us = t_us;
  return e;
}

TEST(SensorEventOrderer, ReleasesInTimeOrderOnceTheImuPassed) {
  SensorEventOrderer o(SensorEventOrdererOptions{0.3});
  SensorEvent out;
  // Arrival: frame at 10 (its channel was quicker), ground truth at 10, IMU at 5 and 10.
  EXPECT_TRUE(o.push(event(SensorEventType::kFeatures, 10), 0.0));
  EXPECT_TRUE(o.push(event(SensorEventType::kGroundTruth, 10), 0.0));
  EXPECT_FALSE(o.pop(0.01, false, &out, nullptr));  // no IMU up to 10 yet
  EXPECT_TRUE(o.push(event(SensorEventType::kImu, 5), 0.0));
  ASSERT_TRUE(o.pop(0.01, false, &out, nullptr));
  EXPECT_EQ(out.t_us, 5);
  EXPECT_FALSE(o.pop(0.01, false, &out, nullptr));
  EXPECT_TRUE(o.push(event(SensorEventType::kImu, 10), 0.0));
  std::vector<SensorEventType> order;
  while (o.pop(0.01, false, &out, nullptr)) order.push_back(out.type);
  EXPECT_EQ(order,
            (std::vector<SensorEventType>{SensorEventType::kImu, SensorEventType::kGroundTruth,
                                          SensorEventType::kFeatures}));
  // Older than what was released: late, dropped, counted.
  EXPECT_FALSE(o.push(event(SensorEventType::kImu, 7), 0.1));
  EXPECT_EQ(o.late(), 1);
  // Without IMU past it, a frame waits max_wait_s, or goes at once when flushing.
  EXPECT_TRUE(o.push(event(SensorEventType::kFeatures, 20), 1.0));
  double arrival = 0.0;
  EXPECT_FALSE(o.pop(1.1, false, &out, &arrival));
  EXPECT_TRUE(o.pop(1.31, false, &out, &arrival));
  EXPECT_EQ(arrival, 1.0);
  EXPECT_TRUE(o.push(event(SensorEventType::kFeatures, 30), 2.0));
  EXPECT_TRUE(o.pop(2.0, true, &out, nullptr));
  EXPECT_EQ(o.releasedUpTo(), 30);
  EXPECT_EQ(o.size(), 0u);
}

}  // namespace
}  // namespace cvslam
