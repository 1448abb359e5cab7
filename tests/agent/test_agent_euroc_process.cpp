// cvslam_agent on EuRoC-format folders (docs/run_format.md): calibration from the folder's
// sensor.yaml files, start at the first ground-truth pose, rendered images through the real
// front end; a start at rest on the real EuRoC micro sequence, also through
// scripts/run_dataset.sh; and a clean end on SIGTERM.
// A start in motion (no rest, no ground truth) on a folder written as a real rig records it.
// Ports 27820–27829.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <thread>

#include "agent_test_util.h"
#include "cvslam/dataset/euroc_dataset_writer.h"
#include "cvslam/io/tum_trajectory.h"
#include "test_paths.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

TEST(AgentEurocProcess, CalibrationFromTheFolderAndStartAtTheGroundTruth) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 4.0, true);
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_SIMULATE_EXE, "--scenario", scenario, "--out", tmp / "data"},
                      tmp / "sim", nullptr, &err, 120s),
            0)
      << err;
  const std::string url = test::agentUrl(27820) + "&recv_buf_size=16777216";
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "1", "--calibration", tmp / "data/uav1", "--lcm-url",
                     url, "--out", tmp / "lcm", "--idle-exit", "3"},
                    tmp / "a1");
  test::Child replay({CVSLAM_REPLAY_EXE, "--dataset", "1:" + tmp / "data/uav1", "--lockstep",
                      "--lockstep-timeout", "30", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(120s), 0) << replay.err();
  EXPECT_EQ(agent.wait(30s), 0) << agent.err();
  EXPECT_NE(agent.out().find("UAV1: 41 frames"), std::string::npos) << agent.out();
  EXPECT_TRUE(std::filesystem::exists(tmp / "lcm/agent_1/frontend.csv"));
  // The one frontend.csv layout of both programs (docs/run_format.md), one row per frame.
  const std::string frontend = test::slurp(tmp / "lcm/agent_1/frontend.csv");
  EXPECT_EQ(frontend.substr(0, frontend.find('\n')),
            "t,observations,predictions,gated_pairs,associated,initialised,front_end_ms,"
            "association_ms,filter_ms,loop_candidates,loop_inliers");
  EXPECT_EQ(std::count(frontend.begin(), frontend.end(), '\n'), 42) << frontend;
  const auto ate = test::ateOf(tmp / "lcm", tmp / "eval");
  ASSERT_EQ(ate.count(1), 1u) << agent.out() << agent.err();
  EXPECT_LT(ate.at(1), 0.5);
}

// A start without ground truth on real data: EuRoC V1_01's first 95 stereo frames with its
// real IMU (MAV standing on the floor, rotors shaking the IMU, IMU mounted x up), the agent
// started at rest from the first second of IMU. The estimate must stay where it started
// (within 1 cm), and match the ground truth after a 4-DoF alignment.
TEST(AgentEurocProcess, StartsAtRestOnTheRealMicroSequence) {
  test::TempFolder tmp;
  const std::string euroc = test::sharedDataDir() + "/euroc_micro";
  const std::string url = test::agentUrl(27822) + "&recv_buf_size=16777216";
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "1", "--calibration", euroc, "--start", "rest",
                     "--lcm-url", url, "--out", tmp / "lcm", "--idle-exit", "3", "--verbose"},
                    tmp / "a1");
  // The folder holds 145 s of IMU but 4.7 s of frames: replay the frames' span only, so that
  // no burst of IMU messages after the last frame floods the loopback under a loaded CI.
  test::Child replay({CVSLAM_REPLAY_EXE, "--dataset", "1:" + euroc, "--lockstep",
                      "--lockstep-timeout", "30", "--lcm-url", url, "--quiet", "--duration", "5"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(180s), 0) << replay.err();
  EXPECT_EQ(agent.wait(60s), 0) << agent.err();
  EXPECT_NE(agent.err().find("started at rest"), std::string::npos) << agent.err();
  EXPECT_NE(agent.out().find("UAV1: 75 frames"), std::string::npos) << agent.out();  // 95 − 1 s
  auto trajectory = readTumTrajectory(tmp / "lcm/agent_1/trajectory.tum");
  ASSERT_TRUE(trajectory.ok()) << trajectory.status().message();
  ASSERT_EQ(trajectory->size(), 75u);
  double farthest = 0.0;
  for (const TumPose& p : *trajectory) farthest = std::max(farthest, p.p_BinN.norm());
  EXPECT_LT(farthest, 0.01) << "the standing MAV's estimate moved";
  EXPECT_NE(test::slurp(tmp / "lcm/agent_1/config_used.yaml").find("start: rest"),
            std::string::npos);
  const auto ate = test::ateOf(tmp / "lcm", tmp / "eval", "yaw");
  ASSERT_EQ(ate.count(1), 1u) << agent.out() << agent.err();
  EXPECT_LT(ate.at(1), 0.01);
}

// start: rest on a recording whose vehicle accelerates within its first second: one line,
// exit 2. (A steady flight would pass: an IMU cannot tell rest from constant velocity or a
// steady turn, whose rate it takes for a gyro bias — docs/filter.md.)
TEST(AgentEurocProcess, StartAtRestRefusesAMovingVehicle) {
  test::TempFolder tmp;
  EurocWriterOptions o;
  o.camera.width = 64;
  o.camera.height = 48;
  auto w = EurocDatasetWriter::create(tmp / "moving", o);
  ASSERT_TRUE(w.ok()) << w.status().message();
  const cv::Mat img(48, 64, CV_8UC1, cv::Scalar(90));
  for (int k = 0; k <= 400; ++k) {  // 2 s at 200 Hz, level, accelerating forward after 0.5 s
    ImuSample m;
    m.t_us = 1000000 + k * 5000;
    m.accel_B = Eigen::Vector3d(k > 100 ? 1.0 : 0.0, 0.0, -9.81);
    ASSERT_TRUE(w->addImu(m).ok());
    if (k % 10 == 0) {
      ASSERT_TRUE(w->addStereoFrame(m.t_us * 1000, img, img).ok());
    }
  }
  ASSERT_TRUE(w->close().ok());
  const std::string url = test::agentUrl(27823);
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "1", "--calibration", tmp / "moving", "--start",
                     "rest", "--lcm-url", url, "--idle-exit", "3"},
                    tmp / "a1");
  test::Child replay({CVSLAM_REPLAY_EXE, "--dataset", "1:" + tmp / "moving", "--lcm-url", url,
                      "--quiet", "--rate", "2"},
                     tmp / "replay");
  replay.wait(60s);
  EXPECT_EQ(agent.wait(30s), 2) << agent.out() << agent.err();
  const std::string e = agent.err();
  EXPECT_NE(e.find("cvslam_agent: static initialisation: the vehicle is not at rest in the first "
                   "1.000 s (mean specific force changes by"),
            std::string::npos)
      << e;
  EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 1) << e;
}

// scripts/run_dataset.sh: the one command for a recorded folder (replay + agent at rest +
// evaluation with the 4-DoF alignment + plots) on the real micro sequence; a bad folder is one
// line and exit 2.
TEST(AgentEurocProcess, RunDatasetScriptOnTheRealMicroSequence) {
  test::TempFolder tmp;
  const std::string build = std::filesystem::path(CVSLAM_EVAL_EXE).parent_path().parent_path();
  const std::string script = test::sourceDir() + "/scripts/run_dataset.sh";
  std::string out, err;
  ASSERT_EQ(test::run({"/bin/bash", script, test::sharedDataDir() + "/euroc_micro", "--out",
                       tmp / "run", "--duration", "5", "--build", build, "--lcm-url",
                       test::agentUrl(27824) + "&recv_buf_size=16777216"},
                      tmp / "script", &out, &err, 180s),
            0)
      << out << err;
  auto summary = readJsonFile(tmp / "run/summary.json");
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_EQ(summary->at("alignment"), "yaw");
  const Json& ate = summary->at("agents").at("1").at("ate_rmse_m");
  ASSERT_TRUE(ate.is_number()) << summary->dump();
  EXPECT_LT(ate.get<double>(), 0.01);
  // One vehicle's recording runs the room map: the full map, bounded (run_dataset.sh --map).
  const std::string config = test::slurp(tmp / "run/agent_1/config_used.yaml");
  EXPECT_NE(config.find("kind: full"), std::string::npos) << config;
  EXPECT_NE(config.find("max_landmarks: 500"), std::string::npos) << config;

  EXPECT_EQ(
      test::run({"/bin/bash", script, test::sharedDataDir() + "/euroc_micro", "--map", "octree"},
                tmp / "bad_map", &out, &err, 30s),
      2);
  EXPECT_NE(err.find("run_dataset.sh: --map must be room or knearest"), std::string::npos) << err;
  EXPECT_EQ(test::run({"/bin/bash", script, tmp / "nothing_here"}, tmp / "bad", &out, &err, 30s),
            2);
  EXPECT_NE(err.find("run_dataset.sh: " + tmp / "nothing_here" + ": no mav0/ folder"),
            std::string::npos)
      << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

// start: auto on a folder written as the VI-sensor records it (cvslam_simulate --as-recorded:
// z-up world, IMU x up, distorted images, EuRoC-like turn-on biases) that begins in mid-flight
// along the real V1_02 trajectory: no rest, so the agent initialises in motion from its first
// second of frames and IMU, and then tracks the flight.
TEST(AgentEurocProcess, StartsInMotionOnAnAsRecordedFlight) {
  test::TempFolder tmp;
  const std::string data = test::sharedDataDir();
  std::ofstream(tmp / "s.yaml")
      << "name: in_flight\nseed: 5\nduration: 4.0\n"
         "render: {world: {kind: hall, seed: 11, hall: {min_N: [-4.5, -5.0, -4.2],"
         " max_N: [4.5, 4.5, -0.85]}}}\n"
         "agents:\n  - id: 1\n"
         "    trajectory: {kind: tum, file: "
      << data
      << "/euroc/V1_02_medium.tum,"
         " z_up_to_ned: true, knot_interval: 0.1, R_TtoB: [0, 0, 1, 0, 1, 0, -1, 0, 0],"
         " time_offset: 15.0}\n"
         "    imu: {rate_hz: 200, gyro_bias: [0.0758, 0.0207, 0.0022],"
         " accel_bias: [0.0931, 0.1035, 0.0133]}\n"
         "    camera: {fx: 458.654, fy: 457.296, cx: 367.215, cy: 248.375, width: 752,"
         " height: 480, baseline: 0.110078, R_BtoC: [-0.025774, 0.999557, -0.014866,"
         " 0.003756, 0.014967, 0.999881, 0.999661, 0.025716, -0.004140],"
         " p_CinB: [0.00981073, -0.06467699, 0.02164015], min_depth: 0.3}\n"
         "    camera_rate_hz: 20.0\n";
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_SIMULATE_EXE, "--scenario", tmp / "s.yaml", "--out", tmp / "data",
                       "--as-recorded", data + "/euroc_micro/mav0", "--quiet"},
                      tmp / "sim", nullptr, &err, 120s),
            0)
      << err;
  const std::string url = test::agentUrl(27825) + "&recv_buf_size=16777216";
  test::Child agent(
      {CVSLAM_AGENT_EXE, "--id", "1", "--calibration", tmp / "data/uav1", "--start", "auto",
       "--lcm-url", url, "--out", tmp / "lcm", "--idle-exit", "3", "--verbose"},
      tmp / "a1");
  test::Child replay({CVSLAM_REPLAY_EXE, "--dataset", "1:" + tmp / "data/uav1", "--lockstep",
                      "--lockstep-timeout", "30", "--lcm-url", url, "--quiet"},
                     tmp / "replay");
  EXPECT_EQ(replay.wait(180s), 0) << replay.err();
  EXPECT_EQ(agent.wait(60s), 0) << agent.err();
  EXPECT_NE(agent.err().find("not at rest"), std::string::npos) << agent.err();
  EXPECT_NE(agent.err().find("started in motion"), std::string::npos) << agent.err();
  auto trajectory = readTumTrajectory(tmp / "lcm/agent_1/trajectory.tum");
  ASSERT_TRUE(trajectory.ok()) << trajectory.status().message();
  EXPECT_GE(trajectory->size(), 55u);  // 81 frames, about 1 s of them before the start
  const auto ate = test::ateOf(tmp / "lcm", tmp / "eval", "yaw");
  ASSERT_EQ(ate.count(1), 1u) << agent.out() << agent.err();
  EXPECT_LT(ate.at(1), 0.1);
}

TEST(AgentEurocProcess, SigtermEndsCleanly) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 4.0, true);
  test::Child agent({CVSLAM_AGENT_EXE, "--id", "2", "--scenario", scenario, "--lcm-url",
                     test::agentUrl(27821), "--out", tmp / "lcm"},
                    tmp / "a2");
  std::this_thread::sleep_for(1s);
  ASSERT_FALSE(agent.exited()) << agent.err();
  kill(agent.pid(), SIGTERM);
  EXPECT_EQ(agent.wait(10s), 0) << agent.err();
  EXPECT_NE(agent.out().find("UAV2: 0 frames"), std::string::npos) << agent.out();
}

}  // namespace
}  // namespace cvslam
