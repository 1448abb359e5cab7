// cvslam_simulate as a process: the EuRoC folders it writes read back (EurocDataset) to
// exactly what the simulator and renderer produce; a noise-free dataset's IMU integrates back
// to its ground truth; bad input gives one clear line and exit status 2.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/sim_test_helpers.h"
#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/scenario/imu_recording.h"
#include "cvslam/sensors/merged_sensor_source.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/simrun/simulated_sensor_stream.h"
#include "euroc_test_folder.h"
#include "process_util.h"
#include "small_scenario.h"
#include "test_paths.h"

namespace cvslam {
namespace {

int simulate(const std::vector<std::string>& extra, const std::string& log, std::string* err) {
  std::vector<std::string> args = {CVSLAM_SIMULATE_EXE, "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run(args, log, nullptr, err);
}

TEST(SimulateProcess, ReadBackEqualsTheSimulation) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 1.0, true);
  std::string err;
  ASSERT_EQ(simulate({"--scenario", scenario, "--out", tmp / "out"}, tmp / "sim", &err), 0) << err;

  // The same simulation in this process.
  auto sc = sim::Scenario::loadFile(scenario);
  ASSERT_TRUE(sc.ok());
  SimulatedSensorOptions o;
  const auto choice = chooseRenderWorld(*sc, "");
  o.render_world = choice->options;
  o.render_options = choice->render;
  auto team = simulateTeam(*sc, o);
  ASSERT_TRUE(team.ok());
  MergedSensorSource source(std::move(team->streams));
  std::map<int, std::vector<SensorEvent>> imu, gt, frames;
  SensorEvent e;
  while (source.next(e)) {
    auto& list = e.type == SensorEventType::kImu           ? imu
                 : e.type == SensorEventType::kGroundTruth ? gt
                                                           : frames;
    list[e.agent_id].push_back(e);
  }
  for (int id : {1, 2}) {
    SCOPED_TRACE(id);
    auto d = EurocDataset::open(tmp / ("out/uav" + std::to_string(id)));
    ASSERT_TRUE(d.ok()) << d.status().message();
    ASSERT_EQ(d->imu().size(), imu[id].size());
    for (std::size_t i = 0; i < d->imu().size(); ++i) {
      EXPECT_EQ(d->imu()[i].t_us, imu[id][i].t_us);
      EXPECT_EQ(d->imu()[i].gyro_B, imu[id][i].imu.gyro_B);  // 17 digits: exact
      EXPECT_EQ(d->imu()[i].accel_B, imu[id][i].imu.accel_B);
    }
    ASSERT_EQ(d->groundTruth().size(), gt[id].size());
    for (std::size_t i = 0; i < gt[id].size(); ++i) {
      const EurocGroundTruth& g = d->groundTruth()[i];
      const VehiclePose& p = gt[id][i].truth;
      EXPECT_EQ(g.t_ns, gt[id][i].t_us * 1000);
      EXPECT_EQ(g.p_SinR, p.p_BinN);
      EXPECT_EQ(g.q_StoR.coeffs(), p.q_BtoN.coeffs());
      EXPECT_EQ(g.v_SinR, p.v_N);
    }
    ASSERT_EQ(d->frameCount(), frames[id].size());
    EXPECT_EQ(d->frameCount(), 11u);
    for (std::size_t i = 0; i < d->frameCount(); ++i) {
      auto f = d->loadFrame(i);
      ASSERT_TRUE(f.ok()) << f.status().message();
      EXPECT_EQ(f->t_ns, frames[id][i].t_us * 1000);
      EXPECT_EQ(cv::norm(f->left, frames[id][i].left, cv::NORM_INF), 0.0);  // PNG: lossless
      EXPECT_EQ(cv::norm(f->right, frames[id][i].right, cv::NORM_INF), 0.0);
    }
    // Calibration as EuRoC writes it: the scenario's (default) camera, rectified.
    ASSERT_TRUE(d->cam0Info().has_value());
    const StereoCameraOptions cam;
    EXPECT_EQ(d->cam0Info()->intrinsics, Eigen::Vector4d(cam.fx, cam.fy, cam.cx, cam.cy));
    EXPECT_EQ(d->cam0Info()->width, cam.width);
    EXPECT_LT((d->cam0Info()->T_BS.topLeftCorner<3, 3>() - cam.R_BtoC.transpose()).norm(), 1e-15);
    ASSERT_TRUE(d->cam1Info().has_value());
    EXPECT_NEAR(
        (d->cam1Info()->T_BS.topRightCorner<3, 1>() - d->cam0Info()->T_BS.topRightCorner<3, 1>())
            .norm(),
        cam.baseline, 1e-12);
    ASSERT_TRUE(d->imuInfo().has_value());
    EXPECT_EQ(d->imuInfo()->rate_hz, 200.0);
  }
  EXPECT_TRUE(std::filesystem::file_size(tmp / "out/landmarks.csv") > 100);
  std::ifstream yaml(tmp / "out/sensors.yaml");
  std::stringstream text;
  text << yaml.rdbuf();
  EXPECT_NE(text.str().find("aerial (outdoor scenario)"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("folder: uav2"), std::string::npos);
}

// RK4 strapdown integration over the recorded samples (step 2 samples: k, k+1 as the
// midpoint, k+2), started from the recorded ground truth; g_R = gravity in the ground
// truth's frame R (NED: +9.81 z, z-up: −9.81 z).
sim::simtest::NavState integrateImu(const std::vector<ImuSample>& imu,
                                    const EurocGroundTruth& start, const Eigen::Vector3d& g) {
  sim::simtest::NavState x{start.q_StoR.toRotationMatrix(), start.v_SinR, start.p_SinR};
  struct D {
    Eigen::Matrix3d dR;
    Eigen::Vector3d dv, dp;
  };
  auto f = [&](const sim::simtest::NavState& s, const ImuSample& m) {
    return D{s.R_BtoN * sim::simtest::skew(m.gyro_B), s.R_BtoN * m.accel_B + g, s.v_N};
  };
  auto add = [](const sim::simtest::NavState& s, const D& k, double h) {
    return sim::simtest::NavState{s.R_BtoN + h * k.dR, s.v_N + h * k.dv, s.p_N + h * k.dp};
  };
  for (std::size_t k = 0; k + 2 < imu.size(); k += 2) {
    const double h = 1e-6 * static_cast<double>(imu[k + 2].t_us - imu[k].t_us);
    const D k1 = f(x, imu[k]);
    const D k2 = f(add(x, k1, h / 2), imu[k + 1]);
    const D k3 = f(add(x, k2, h / 2), imu[k + 1]);
    const D k4 = f(add(x, k3, h), imu[k + 2]);
    x.R_BtoN += h / 6 * (k1.dR + 2 * k2.dR + 2 * k3.dR + k4.dR);
    x.v_N += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
    x.p_N += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(x.R_BtoN, Eigen::ComputeFullU | Eigen::ComputeFullV);
    x.R_BtoN = svd.matrixU() * svd.matrixV().transpose();
  }
  return x;
}

TEST(SimulateProcess, NoiseFreeImuIntegratesToTheGroundTruth) {
  test::TempFolder tmp;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 4.0, false);
  std::string err;
  ASSERT_EQ(simulate({"--scenario", scenario, "--out", tmp / "out"}, tmp / "sim", &err), 0) << err;
  for (int id : {1, 2}) {
    SCOPED_TRACE(id);
    auto d = EurocDataset::open(tmp / ("out/uav" + std::to_string(id)));
    ASSERT_TRUE(d.ok()) << d.status().message();
    const auto& gt = d->groundTruth();
    ASSERT_EQ(d->imu().size(), 801u);
    ASSERT_EQ(gt.size(), 801u);
    const sim::simtest::NavState x = integrateImu(d->imu(), gt[0], Eigen::Vector3d(0, 0, 9.81));
    const EurocGroundTruth& end = gt.back();
    EXPECT_LT((x.p_N - end.p_SinR).norm(), 1e-4);
    EXPECT_LT((x.v_N - end.v_SinR).norm(), 1e-4);
    EXPECT_LT((x.R_BtoN - end.q_StoR.toRotationMatrix()).norm(), 1e-6);
    // And it really moved: metres, not a hover.
    EXPECT_GT((end.p_SinR - gt[0].p_SinR).norm(), 5.0);
  }
}

// --as-recorded: the real rig's calibration in sensor.yaml, a recorder's clock, a z-up world
// and the IMU in the rig's axes — checked by physics: at rest the accelerometer reads gravity
// in the IMU axes of the ground-truth attitude, and the IMU integrates (z-up gravity) to the
// ground truth after take-off.
TEST(SimulateProcess, AsRecordedFolderIsARealRigsRecording) {
  test::TempFolder tmp;
  std::string yaml = test::smallScenarioYaml(4.0, false);
  const std::string needle = "tilt: quadrotor}";
  yaml.replace(yaml.find(needle), needle.size(), "tilt: quadrotor, rest: 1.0, rest_ramp: 1.0}");
  std::ofstream(tmp / "s.yaml") << yaml;
  const std::string mav0 = test::sharedDataDir() + "/euroc_micro/mav0";
  std::string err;
  ASSERT_EQ(simulate({"--scenario", tmp / "s.yaml", "--out", tmp / "out", "--as-recorded", mav0},
                     tmp / "sim", &err),
            0)
      << err;
  auto real = EurocDataset::open(test::sharedDataDir() + "/euroc_micro");
  ASSERT_TRUE(real.ok());
  auto d = EurocDataset::open(tmp / "out/uav1");
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_TRUE(d->cam0Info() && d->cam1Info());
  EXPECT_LT((d->cam0Info()->T_BS - real->cam0Info()->T_BS).norm(), 1e-12);
  EXPECT_LT((d->cam1Info()->T_BS - real->cam1Info()->T_BS).norm(), 1e-12);
  EXPECT_EQ(d->cam0Info()->distortion, real->cam0Info()->distortion);
  EXPECT_EQ(d->imageSize(), cv::Size(752, 480));
  EXPECT_EQ(d->frameCount(), 41u);  // 10 Hz over 0..4 s

  const auto& gt = d->groundTruth();
  const auto& imu = d->imu();
  ASSERT_EQ(imu.size(), 801u);
  EXPECT_GE(gt.front().t_ns, int64_t{1'400'000'000'000'000'000});  // a recorder's clock
  for (std::size_t k = 0; k < 190; ++k) {  // standing still for the first second
    SCOPED_TRACE(k);
    EXPECT_LT((gt[k].p_SinR - gt[0].p_SinR).norm(), 1e-12);
    const Eigen::Vector3d f_S = gt[k].q_StoR.conjugate() * Eigen::Vector3d(0, 0, 9.81);
    EXPECT_LT((imu[k].accel_B - f_S).norm(), 1e-9);
    EXPECT_LT(imu[k].gyro_B.norm(), 1e-12);
  }
  const sim::simtest::NavState x = integrateImu(imu, gt[0], Eigen::Vector3d(0, 0, -9.81));
  EXPECT_LT((x.p_N - gt.back().p_SinR).norm(), 1e-3);
  EXPECT_LT((x.R_BtoN - gt.back().q_StoR.toRotationMatrix()).norm(), 1e-5);
  EXPECT_GT((gt.back().p_SinR - gt[0].p_SinR).norm(), 3.0);
  // The world is z-up: the flight 10 m above N's ground is at z ≈ +10.
  EXPECT_GT(gt[0].p_SinR.z(), 5.0);
  auto frame = d->loadFrame(20);
  ASSERT_TRUE(frame.ok());
  cv::Scalar mean, stddev;
  cv::meanStdDev(frame->left, mean, stddev);
  EXPECT_GT(stddev[0], 10.0);  // textured, not background
}

// The EuRoC hall scenario: rendered in the hall with EuRoC's camera, UAV 3 carrying the real
// MH_03 IMU (rotated into FRD), calibration written as EuRoC does.
TEST(SimulateProcess, EurocHallScenarioWithTheRealImu) {
  test::TempFolder tmp;
  std::string err;
  ASSERT_EQ(simulate({"--scenario", test::sourceDir() + "/config/scenarios/euroc_mh03_hall.yaml",
                      "--out", tmp / "out", "--duration", "0.2"},
                     tmp / "sim", &err),
            0)
      << err;
  auto d = EurocDataset::open(tmp / "out/uav3");
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_TRUE(d->cam0Info().has_value());
  EXPECT_EQ(d->cam0Info()->intrinsics, Eigen::Vector4d(458.654, 457.296, 367.215, 248.375));
  EXPECT_EQ(d->imageSize(), cv::Size(752, 480));
  EXPECT_EQ(d->frameCount(), 5u);  // 20 Hz, 0..0.2 s
  auto f = d->loadFrame(2);
  ASSERT_TRUE(f.ok());
  cv::Scalar mean, stddev;
  cv::meanStdDev(f->left, mean, stddev);
  EXPECT_GT(stddev[0], 10.0);  // textured hall, not background
  Eigen::Matrix3d R_StoB;
  R_StoB << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  auto rec =
      sim::ImuRecording::load(test::sharedDataDir() + "/euroc/imu/MH_03_medium_imu0.csv", R_StoB);
  ASSERT_TRUE(rec.ok());
  ASSERT_EQ(d->imu().size(), 41u);
  for (const ImuSample& s : d->imu()) {
    const ImuSample want =
        (*rec)->sampleAt(1403637132.88832 + 1e-6 * static_cast<double>(s.t_us), 0);
    EXPECT_LT((s.accel_B - want.accel_B).norm(), 1e-12);
    EXPECT_LT((s.gyro_B - want.gyro_B).norm(), 1e-12);
  }
  std::ifstream yaml(tmp / "out/sensors.yaml");
  std::stringstream text;
  text << yaml.rdbuf();
  EXPECT_NE(text.str().find("render_world: \"hall"), std::string::npos) << text.str();
}

TEST(SimulateProcess, BadInputGivesOneLineAndStatus2) {
  test::TempFolder tmp;
  std::string err;
  EXPECT_EQ(simulate({"--out", tmp / "o"}, tmp / "a", &err), 2);
  EXPECT_NE(err.find("--scenario is required"), std::string::npos) << err;
  EXPECT_EQ(simulate({"--scenario", tmp / "none.yaml", "--out", tmp / "o"}, tmp / "b", &err), 2);
  EXPECT_NE(err.find("none.yaml"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  const std::string scenario = test::writeSmallScenario(tmp / "s.yaml", 0.2, true);
  EXPECT_EQ(
      simulate({"--scenario", scenario, "--out", tmp / "o", "--world", "moon"}, tmp / "c", &err),
      2);
  EXPECT_NE(err.find("unknown world 'moon'"), std::string::npos) << err;
  ASSERT_EQ(simulate({"--scenario", scenario, "--out", tmp / "o"}, tmp / "d", &err), 0) << err;
  // Never mixes two datasets.
  EXPECT_EQ(simulate({"--scenario", scenario, "--out", tmp / "o"}, tmp / "e", &err), 2);
  EXPECT_NE(err.find("mav0"), std::string::npos) << err;
  std::string out;
  EXPECT_EQ(test::run({CVSLAM_SIMULATE_EXE, "--help"}, tmp / "h", &out), 0);
  EXPECT_NE(out.find("usage: cvslam_simulate"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
