#include "cvslam/dataset/euroc_dataset.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cvslam/dataset/euroc_dataset_writer.h"
#include "euroc_test_folder.h"
#include "test_paths.h"

namespace cvslam {
namespace {

namespace fs = std::filesystem;

std::string microPath() {
  return test::sharedDataDir() + "/euroc_micro";
}

TEST(EurocDataset, ReadsTheRealMicroSequence) {
  auto d = EurocDataset::open(microPath());
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->frameCount(), 95u);
  EXPECT_EQ(d->unpairedLeft(), 0);
  EXPECT_EQ(d->unpairedRight(), 4);  // cam1 lists four more frames than cam0
  EXPECT_EQ(d->imageSize(), cv::Size(752, 480));
  EXPECT_EQ(d->frameTimeNs(0), 1403715273262142976);
  // 20 Hz: consecutive paired frames 50 ms apart.
  EXPECT_NEAR(static_cast<double>(d->frameTimeNs(1) - d->frameTimeNs(0)), 5e7, 1e3);

  ASSERT_EQ(d->imu().size(), 29120u);
  const ImuSample& m = d->imu().front();
  EXPECT_EQ(m.t_us, 1403715273262143);  // rounded from ...262142976 ns
  EXPECT_DOUBLE_EQ(m.gyro_B.x(), -0.0020943951023931952);
  EXPECT_DOUBLE_EQ(m.accel_B.x(), 9.0874956666666655);
  EXPECT_DOUBLE_EQ(m.accel_B.z(), -3.6938381666666662);
  EXPECT_EQ(d->imuTimesNs().front(), 1403715273262142976);

  ASSERT_TRUE(d->hasGroundTruth());
  ASSERT_EQ(d->groundTruth().size(), 2895u);
  const EurocGroundTruth& g = d->groundTruth().front();
  EXPECT_DOUBLE_EQ(g.p_SinR.x(), 0.878895);
  EXPECT_DOUBLE_EQ(g.q_StoR.w(), 0.069433);
  EXPECT_DOUBLE_EQ(g.q_StoR.x(), -0.824237);
  EXPECT_DOUBLE_EQ(g.accel_bias.z(), 0.0309774);

  ASSERT_TRUE(d->cam0Info().has_value());
  EXPECT_DOUBLE_EQ(d->cam0Info()->intrinsics(0), 458.654);
  EXPECT_EQ(d->cam0Info()->distortion.size(), 4u);
  EXPECT_DOUBLE_EQ(d->cam0Info()->T_BS(0, 3), -0.0216401454975);
  ASSERT_TRUE(d->imuInfo().has_value());
  EXPECT_DOUBLE_EQ(d->imuInfo()->gyroscope_noise_density, 1.6968e-04);

  auto f = d->loadFrame(94);
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_EQ(f->left.type(), CV_8UC1);
  EXPECT_EQ(f->right.size(), cv::Size(752, 480));
  EXPECT_GT(cv::mean(f->left)[0], 10.0);
  EXPECT_FALSE(d->loadFrame(95).ok());
}

TEST(EurocDataset, AcceptsTheMav0FolderItself) {
  auto d = EurocDataset::open(microPath() + "/mav0");
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->frameCount(), 95u);
}

// A small valid dataset (3 frames of 64×48, IMU, ground truth) to break in each test.
class BrokenEuroc : public ::testing::Test {
 protected:
  void SetUp() override {
    EurocWriterOptions o;
    o.camera.width = 64;
    o.camera.height = 48;
    auto w = EurocDatasetWriter::create(tmp_.path(), o);
    ASSERT_TRUE(w.ok()) << w.status().message();
    for (int k = 0; k < 3; ++k) {
      cv::Mat img(48, 64, CV_8UC1, cv::Scalar(40 * k + 20));
      ASSERT_TRUE(w->addStereoFrame(1000000000 + k * 50000000, img, img).ok());
    }
    for (int k = 0; k < 30; ++k) {
      ImuSample m;
      m.t_us = 1000000 + k * 5000;
      m.accel_B.z() = -9.81;
      ASSERT_TRUE(w->addImu(m).ok());
    }
    for (int k = 0; k < 3; ++k) {
      EurocGroundTruth g;
      g.t_ns = 1000000000 + k * 50000000;
      ASSERT_TRUE(w->addGroundTruth(g).ok());
    }
    ASSERT_TRUE(w->close().ok());
    ASSERT_TRUE(EurocDataset::open(tmp_.path()).ok());
  }
  std::string mav0(const std::string& sub) const { return tmp_ / ("mav0/" + sub); }
  // Replaces line `n` (1-based, header included) of a file.
  void editLine(const std::string& file, int n, const std::string& text) {
    std::ifstream in(mav0(file));
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    ASSERT_LE(n, static_cast<int>(lines.size()));
    lines[static_cast<std::size_t>(n - 1)] = text;
    std::ofstream out(mav0(file));
    for (const auto& l : lines) out << l << '\n';
  }
  std::string lineOf(const std::string& file, int n) {
    std::ifstream in(mav0(file));
    std::string l;
    for (int i = 0; i < n; ++i) std::getline(in, l);
    return l;
  }
  // Opening must fail with a message containing every fragment.
  void expectError(std::initializer_list<std::string> fragments) {
    auto d = EurocDataset::open(tmp_.path());
    ASSERT_FALSE(d.ok());
    const std::string& msg = d.status().message();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
    for (const auto& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << msg;
  }
  test::TempFolder tmp_;
};

TEST_F(BrokenEuroc, MissingFolders) {
  fs::remove_all(mav0("cam1/data"));
  expectError({"cam1/data", "folder missing"});
  fs::remove_all(mav0(""));
  expectError({"mav0", "folder missing"});
}

TEST_F(BrokenEuroc, MissingFiles) {
  fs::remove(mav0("imu0/data.csv"));
  expectError({"imu0/data.csv", "missing"});
}

TEST_F(BrokenEuroc, MissingCameraList) {
  fs::remove(mav0("cam0/data.csv"));
  expectError({"cam0/data.csv", "missing"});
}

TEST_F(BrokenEuroc, UnsortedImageTimestamps) {
  const std::string second = lineOf("cam0/data.csv", 3), third = lineOf("cam0/data.csv", 4);
  editLine("cam0/data.csv", 3, third);
  editLine("cam0/data.csv", 4, second);
  expectError({"cam0/data.csv:4:", "before the previous"});
}

TEST_F(BrokenEuroc, DuplicateImuTimestamps) {
  const std::string row = lineOf("imu0/data.csv", 5);
  editLine("imu0/data.csv", 6, row);
  expectError({"imu0/data.csv:6:", "duplicates"});
}

TEST_F(BrokenEuroc, MalformedCsvLines) {
  editLine("imu0/data.csv", 3, "1000005000000,0,0,0,0,0");
  expectError({"imu0/data.csv:3:", "expected 7", "got 6"});
}

TEST_F(BrokenEuroc, BadNumberInGroundTruth) {
  std::string row = lineOf("state_groundtruth_estimate0/data.csv", 2);
  row.replace(row.find(','), 2, ",x");
  editLine("state_groundtruth_estimate0/data.csv", 2, row);
  expectError({"state_groundtruth_estimate0/data.csv:2:", "bad number"});
}

TEST_F(BrokenEuroc, BadTimestamp) {
  editLine("cam1/data.csv", 2, "12a4,1000000000.png");
  expectError({"cam1/data.csv:2:", "bad timestamp"});
}

TEST_F(BrokenEuroc, ImageOfTheWrongSize) {
  cv::imwrite(mav0("cam1/data/1050000000.png"), cv::Mat(48, 32, CV_8UC1, cv::Scalar(9)));
  expectError({"cam1/data/1050000000.png", "image is 32x48, expected 64x48"});
}

TEST_F(BrokenEuroc, ImageOfTheWrongSizeWithoutSensorYaml) {
  fs::remove(mav0("cam0/sensor.yaml"));
  fs::remove(mav0("cam1/sensor.yaml"));
  cv::imwrite(mav0("cam0/data/1100000000.png"), cv::Mat(40, 64, CV_8UC1, cv::Scalar(9)));
  expectError({"1100000000.png", "expected 64x48", "first cam0 image"});
}

TEST_F(BrokenEuroc, UnreadablePng) {
  std::ofstream(mav0("cam0/data/1000000000.png")) << "not a png";
  expectError({"cam0/data/1000000000.png", "not a readable PNG"});
}

TEST_F(BrokenEuroc, ListedImageMissing) {
  fs::remove(mav0("cam1/data/1100000000.png"));
  expectError({"cam1/data/1100000000.png", "missing"});
}

TEST_F(BrokenEuroc, CorruptPngDataFailsAtLoad) {
  // A valid header with garbage after it passes open() (headers only) and fails to decode.
  const std::string p = mav0("cam0/data/1050000000.png");
  std::ifstream in(p, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  bytes.resize(40);
  std::ofstream(p, std::ios::binary) << bytes;
  auto d = EurocDataset::open(tmp_.path());
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_TRUE(d->loadFrame(0).ok());
  auto f = d->loadFrame(1);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.status().message().find("1050000000.png: cannot decode PNG"), std::string::npos);
}

TEST_F(BrokenEuroc, MissingImuAtTheStart) {
  // Frames start at 1.000 s; keep the IMU only from 1.130 s on (rows 2–27 are 1.000–1.125 s).
  std::ifstream in(mav0("imu0/data.csv"));
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  in.close();
  std::ofstream out(mav0("imu0/data.csv"));
  out << lines[0] << '\n';
  for (std::size_t k = 27; k < lines.size(); ++k) out << lines[k] << '\n';
  out.close();
  expectError({"imu0/data.csv", "the IMU starts 130 ms after the first stereo frame",
               "missing IMU at the start"});
  std::ofstream(mav0("imu0/data.csv")) << lines[0] << '\n';
  expectError({"imu0/data.csv", "no IMU samples"});
}

TEST_F(BrokenEuroc, NonRigidImuTbs) {
  const std::string yaml = mav0("imu0/sensor.yaml");
  std::ifstream in(yaml);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  std::string s = text.str();
  const auto at = s.find("data: [1");  // identity T_BS: scale its first entry
  ASSERT_NE(at, std::string::npos) << s;
  s.replace(at, 8, "data: [2");
  std::ofstream(yaml) << s;
  expectError({"imu0/sensor.yaml", "T_BS", "not a rotation matrix"});
}

TEST_F(BrokenEuroc, BrokenSensorYaml) {
  std::ofstream(mav0("cam0/sensor.yaml")) << "%YAML:1.0\nresolution: [64]\n";
  expectError({"cam0/sensor.yaml", "T_BS"});
}

TEST_F(BrokenEuroc, ExtraRightFramesAreCountedNotPaired) {
  cv::imwrite(mav0("cam1/data/1125000000.png"), cv::Mat(48, 64, CV_8UC1, cv::Scalar(9)));
  std::ofstream(mav0("cam1/data.csv"), std::ios::app) << "1125000000,1125000000.png\n";
  auto d = EurocDataset::open(tmp_.path());
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->frameCount(), 3u);
  EXPECT_EQ(d->unpairedRight(), 1);
  EXPECT_EQ(d->unpairedLeft(), 0);
}

TEST_F(BrokenEuroc, GroundTruthIsOptional) {
  fs::remove_all(mav0("state_groundtruth_estimate0"));
  auto d = EurocDataset::open(tmp_.path());
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_FALSE(d->hasGroundTruth());
}

}  // namespace
}  // namespace cvslam
