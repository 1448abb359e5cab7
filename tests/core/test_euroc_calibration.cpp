#include "cvslam/camera/euroc_calibration.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/LU>
#include <cstdio>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_paths.h"

namespace cvslam {
namespace {

namespace fs = std::filesystem;

std::string mav0() {
  return test::sharedDataDir() + "/euroc_micro/mav0";
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A temporary copy of cam0/sensor.yaml with one edit, removed at scope exit.
class BrokenCopy {
 public:
  BrokenCopy(const std::string& name, const std::string& from, const std::string& to) {
    path_ = (fs::temp_directory_path() /
             ("cvslam_euroc_" + std::to_string(::getpid()) + "_" + name + ".yaml"))
                .string();
    std::string text = readFile(mav0() + "/cam0/sensor.yaml");
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "fixture text not found: " << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    std::ofstream(path_) << text;
  }
  ~BrokenCopy() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

TEST(EurocCalibration, LoadsTheRealFiles) {
  auto calib = loadEurocStereoCalibration(mav0());
  ASSERT_TRUE(calib.ok()) << calib.status().message();
  const EurocCameraCalibration& l = calib->left;
  EXPECT_DOUBLE_EQ(l.intrinsics(0), 458.654);
  EXPECT_DOUBLE_EQ(l.intrinsics(3), 248.375);
  EXPECT_DOUBLE_EQ(l.distortion(0), -0.28340811);
  EXPECT_DOUBLE_EQ(l.distortion(3), 1.76187114e-05);
  EXPECT_EQ(l.width, 752);
  EXPECT_EQ(l.height, 480);
  EXPECT_DOUBLE_EQ(l.rate_hz, 20.0);
  EXPECT_DOUBLE_EQ(l.T_CtoB(0, 1), -0.999880929698);  // row-major data
  EXPECT_DOUBLE_EQ(l.T_CtoB(1, 3), -0.064676986768);
  EXPECT_DOUBLE_EQ(l.K()(0, 2), 367.215);
  EXPECT_DOUBLE_EQ(calib->right.intrinsics(2), 379.999);
  // The VI-sensor's stereo baseline is about 11 cm, mostly along the left camera's x axis.
  EXPECT_NEAR(calib->baseline(), 0.110, 0.002);
  const Eigen::Vector3d p_LinR = calib->T_LtoR().topRightCorner<3, 1>();
  EXPECT_LT(p_LinR.x(), -0.10);  // the left centre is at −x of the right camera
}

TEST(EurocCalibration, MissingFolderIsAClearError) {
  auto calib = loadEurocStereoCalibration("/nonexistent/mav0");
  ASSERT_FALSE(calib.ok());
  EXPECT_NE(calib.status().message().find("cannot open"), std::string::npos);
}

struct Broken {
  const char* name;
  const char* from;
  const char* to;
  const char* expect;  ///< substring of the error
};

TEST(EurocCalibration, BrokenFilesGiveClearErrors) {
  const Broken broken[] = {
      {"no_intrinsics", "intrinsics:", "intrinsicz:", "intrinsics: required key is missing"},
      {"short_intrinsics", "[458.654, 457.296, 367.215, 248.375]", "[458.654, 457.296]",
       "intrinsics: expected a list of 4"},
      {"bad_number", "458.654", "abc", "intrinsics: expected a number"},
      {"fisheye", "radial-tangential", "equidistant", "distortion_model: only"},
      {"short_T", "0.0, 0.0, 0.0, 1.0]", "0.0, 0.0, 0.0]", "T_BS.data: expected a list of 16"},
      {"no_T", "T_BS:", "T_XX:", "T_BS: required key is missing"},
      {"bad_last_row", "0.0, 0.0, 0.0, 1.0]", "0.0, 0.0, 0.0, 2.0]", "last row"},
      {"bad_rotation", "[0.0148655429818", "[0.5", "not a rotation"},
      {"resolution", "[752, 480]", "[752]", "resolution: expected [width, height]"},
      {"rate", "rate_hz: 20", "rate_hz: -20", "rate_hz: must be > 0"},
      {"yaml", "rate_hz: 20", "rate_hz: [20", "invalid YAML"},
  };
  for (const Broken& b : broken) {
    BrokenCopy copy(b.name, b.from, b.to);
    auto calib = loadEurocCameraCalibration(copy.path());
    ASSERT_FALSE(calib.ok()) << b.name;
    const std::string& msg = calib.status().message();
    EXPECT_NE(msg.find(b.expect), std::string::npos) << b.name << ": " << msg;
    EXPECT_NE(msg.find(copy.path()), std::string::npos) << "names the file: " << msg;
  }
}

}  // namespace
}  // namespace cvslam
