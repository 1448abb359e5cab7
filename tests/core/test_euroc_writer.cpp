#include "cvslam/dataset/euroc_dataset_writer.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/render/stereo_renderer.h"
#include "euroc_test_folder.h"

namespace cvslam {
namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(EurocDatasetWriter, RenderedDatasetReadsBackEqual) {
  test::TempFolder tmp;
  render::WorldOptions wo;
  wo.texture.tile_size = 256;
  wo.texture.tile_count = 2;
  auto world = render::World::create(wo);
  ASSERT_TRUE(world.ok()) << world.status().message();
  StereoCameraOptions cam;
  cam.width = 160;
  cam.height = 120;
  cam.cx = 80;
  cam.cy = 60;
  cam.p_CinB = {0.1, -0.05, 0.02};
  render::RenderOptions ro;
  ro.effects.noise_sigma = 2.0;
  render::StereoRenderer renderer(*world, StereoCamera(cam), ro);

  EurocWriterOptions o;
  o.camera = cam;
  o.imu.gyroscope_noise_density = 1.234e-4;
  auto w = EurocDatasetWriter::create(tmp.path(), o);
  ASSERT_TRUE(w.ok()) << w.status().message();

  std::vector<render::StereoRendering> frames;
  std::vector<ImuSample> imu;
  std::vector<EurocGroundTruth> gt;
  const int64_t t0_ns = 1700000000000000000;
  for (int k = 0; k < 4; ++k) {
    const int64_t t_ns = t0_ns + k * 50000000;
    const Eigen::Vector3d p(0.3 * k, 0.1 * k, -10.0), e(0.01 * k, -0.02, 0.1 * k);
    frames.push_back(renderer.render(p, e, static_cast<uint64_t>(k)));
    ASSERT_TRUE(w->addStereoFrame(t_ns, frames.back().left.image, frames.back().right.image).ok());
    EurocGroundTruth g;
    g.t_ns = t_ns;
    g.p_SinR = p;
    g.q_StoR =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * k + 0.3, Eigen::Vector3d(1, 2, 3).normalized()));
    g.v_SinR = {1.0 / 3.0, -2.0 / 7.0, 0.1 * k};
    g.gyro_bias = {1e-3, -2e-3, 3e-3};
    g.accel_bias = {0.01, 0.02, -0.03 * k};
    gt.push_back(g);
    ASSERT_TRUE(w->addGroundTruth(g).ok());
  }
  for (int k = 0; k < 40; ++k) {
    ImuSample m;
    m.t_us = t0_ns / 1000 + k * 5000;
    m.gyro_B = {std::sin(0.1 * k), std::cos(0.2 * k) / 3.0, 1e-7 * k};
    m.accel_B = {0.1 * std::sin(0.3 * k), 0.2, -9.81 + 1.0 / (k + 1)};
    imu.push_back(m);
    ASSERT_TRUE(w->addImu(m).ok());
  }
  // Out-of-order input is refused.
  EXPECT_FALSE(w->addImu(imu.front()).ok());
  EXPECT_FALSE(w->addStereoFrame(t0_ns, frames[0].left.image, frames[0].right.image).ok());
  ASSERT_TRUE(w->close().ok());

  auto d = EurocDataset::open(tmp.path());
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->frameCount(), frames.size());
  EXPECT_EQ(d->unpairedLeft() + d->unpairedRight(), 0);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    auto f = d->loadFrame(k);
    ASSERT_TRUE(f.ok()) << f.status().message();
    EXPECT_EQ(f->t_ns, t0_ns + static_cast<int64_t>(k) * 50000000);
    EXPECT_EQ(cv::norm(f->left, frames[k].left.image, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(f->right, frames[k].right.image, cv::NORM_INF), 0.0);
  }
  ASSERT_EQ(d->imu().size(), imu.size());
  for (std::size_t k = 0; k < imu.size(); ++k) {
    EXPECT_EQ(d->imu()[k].t_us, imu[k].t_us);
    EXPECT_EQ(d->imu()[k].gyro_B, imu[k].gyro_B);
    EXPECT_EQ(d->imu()[k].accel_B, imu[k].accel_B);
  }
  ASSERT_EQ(d->groundTruth().size(), gt.size());
  for (std::size_t k = 0; k < gt.size(); ++k) {
    const EurocGroundTruth& a = d->groundTruth()[k];
    EXPECT_EQ(a.t_ns, gt[k].t_ns);
    EXPECT_EQ(a.p_SinR, gt[k].p_SinR);
    EXPECT_EQ(a.q_StoR.coeffs(), gt[k].q_StoR.coeffs());
    EXPECT_EQ(a.v_SinR, gt[k].v_SinR);
    EXPECT_EQ(a.gyro_bias, gt[k].gyro_bias);
    EXPECT_EQ(a.accel_bias, gt[k].accel_bias);
  }

  // Calibration: intrinsics, zero distortion, T_BS = T_CtoB; cam1 shifted by the baseline.
  ASSERT_TRUE(d->cam0Info() && d->cam1Info() && d->imuInfo());
  EXPECT_EQ(d->cam0Info()->intrinsics, Eigen::Vector4d(cam.fx, cam.fy, cam.cx, cam.cy));
  EXPECT_EQ(d->cam0Info()->width, 160);
  EXPECT_EQ(d->cam0Info()->distortion, std::vector<double>(4, 0.0));
  EXPECT_EQ(d->cam0Info()->distortion_model, "radial-tangential");
  EXPECT_EQ(d->cam0Info()->camera_model, "pinhole");
  const Eigen::Matrix3d R_CtoB = d->cam0Info()->T_BS.block(0, 0, 3, 3);
  EXPECT_TRUE(R_CtoB.isApprox(cam.R_BtoC.transpose()));
  const Eigen::Vector3d t0 = d->cam0Info()->T_BS.block(0, 3, 3, 1);
  EXPECT_TRUE(t0.isApprox(cam.p_CinB));
  const Eigen::Vector3d p_CRinB = cam.p_CinB + cam.R_BtoC.transpose() * Eigen::Vector3d(0.2, 0, 0);
  const Eigen::Vector3d t1 = d->cam1Info()->T_BS.block(0, 3, 3, 1);
  EXPECT_TRUE(t1.isApprox(p_CRinB));
  EXPECT_DOUBLE_EQ(d->cam0Info()->rate_hz, 20.0);
  EXPECT_DOUBLE_EQ(d->imuInfo()->gyroscope_noise_density, 1.234e-4);
  EXPECT_DOUBLE_EQ(d->imuInfo()->rate_hz, 200.0);

  // The files look like EuRoC's own (what Basalt / OpenVINS parse).
  const std::string yaml = readAll(d->mav0() + "/cam0/sensor.yaml");
  for (const char* key :
       {"%YAML:1.0\n", "T_BS:\n  cols: 4\n  rows: 4\n  data: [", "rate_hz: 20",
        "resolution: [160, 120]", "camera_model: pinhole", "intrinsics: [560, 560, 80, 60]",
        "distortion_model: radial-tangential", "distortion_coefficients: [0, 0, 0, 0]"})
    EXPECT_NE(yaml.find(key), std::string::npos) << key << "\n" << yaml;
  const std::string imu_yaml = readAll(d->mav0() + "/imu0/sensor.yaml");
  for (const char* key : {"%YAML:1.0\n", "gyroscope_noise_density: 0.0001234",
                          "accelerometer_random_walk:", "rate_hz: 200"})
    EXPECT_NE(imu_yaml.find(key), std::string::npos) << key << "\n" << imu_yaml;
  EXPECT_EQ(readAll(d->mav0() + "/cam0/data.csv").rfind("#timestamp [ns],filename\n", 0), 0u);
}

TEST(EurocDatasetWriter, RefusesToOverwriteAndWrongImages) {
  test::TempFolder tmp;
  EurocWriterOptions o;
  o.camera.width = 32;
  o.camera.height = 24;
  auto w = EurocDatasetWriter::create(tmp.path(), o);
  ASSERT_TRUE(w.ok());
  EXPECT_FALSE(w->addStereoFrame(1, cv::Mat(24, 31, CV_8UC1), cv::Mat(24, 32, CV_8UC1)).ok());
  EXPECT_FALSE(w->addStereoFrame(1, cv::Mat(24, 32, CV_8UC3), cv::Mat(24, 32, CV_8UC1)).ok());
  auto again = EurocDatasetWriter::create(tmp.path(), o);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.status().message().find("already exists"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
