#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "cvslam/geometry/euler.h"
#include "cvslam/io/csv_table.h"
#include "cvslam/io/json_file.h"
#include "cvslam/io/run_reader.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/io/tum_trajectory.h"
#include "fake_run.h"

namespace cvslam {
namespace {

namespace fs = std::filesystem;

/// A fresh temporary folder per test, removed at the end.
class RunIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("cvslam_run_io_" + std::to_string(::getpid()) + "_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name())))
               .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
  std::string dir_;
};

TEST_F(RunIo, TumRoundTrip) {
  std::vector<TumPose> poses;
  for (int k = 0; k < 5; ++k) {
    Vector9d x;
    x << k, -k, 2.5, 0, 0, 0, 0.1 * k, -0.05 * k, 3.0 - k;
    poses.push_back(tumPoseFromState(1e9 + 0.05 * k, x));  // large epoch-style times
  }
  const std::string path = dir_ + "/t.tum";
  ASSERT_TRUE(writeTumTrajectory(path, poses).ok());
  auto back = readTumTrajectory(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR((*back)[k].t, poses[k].t, 1e-6);
    EXPECT_LT(((*back)[k].p_BinN - poses[k].p_BinN).norm(), 1e-7);
    EXPECT_LT((*back)[k].q_BtoN.angularDistance(poses[k].q_BtoN), 1e-7);
  }
  // The quaternion is the body's orientation in N: it rotates body x into the heading.
  Vector9d x = Vector9d::Zero();
  x(8) = M_PI / 2;  // yaw 90°: nose east
  EXPECT_LT(
      (tumPoseFromState(0, x).q_BtoN * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
      1e-12);
}

TEST_F(RunIo, TumErrorsNameFileAndLine) {
  struct Bad {
    const char* text;
    const char* expect;
  };
  const Bad bad[] = {
      {"# c\n0 1 2 3 0 0 0 1\n1 1 2 3 0 0 1\n", ":3: expected 8 fields"},
      {"0 1 2 3 0 0 0 1\n1 1 x 3 0 0 0 1\n", ":2: not a finite number: 'x'"},
      {"0 1 2 3 0 0 0 1\n2 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 1\n", ":3: time 1 s is not after"},
      {"0 1 2 3 0 0 0 0\n", ":1: zero quaternion"},
  };
  for (const Bad& b : bad) {
    const std::string path = write("bad.tum", b.text);
    auto r = readTumTrajectory(path);
    ASSERT_FALSE(r.ok()) << b.text;
    EXPECT_NE(r.status().message().find(path + b.expect), std::string::npos)
        << r.status().message();
  }
  EXPECT_FALSE(readTumTrajectory(dir_ + "/missing.tum").ok());
}

TEST_F(RunIo, CsvTable) {
  auto ok = readCsvTable(write("a.csv", "#id, x ,y\n1,2,3\n\n# note\n4, 5.5 ,nan\n"), {"x"});
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->header, (std::vector<std::string>{"id", "x", "y"}));
  ASSERT_EQ(ok->rows.size(), 2u);
  EXPECT_DOUBLE_EQ(ok->rows[1][1], 5.5);
  EXPECT_TRUE(std::isnan(ok->rows[1][2]));
  EXPECT_EQ(ok->line_numbers[1], 5);
  auto short_row = readCsvTable(write("b.csv", "a,b\n1,2\n3\n"));
  ASSERT_FALSE(short_row.ok());
  EXPECT_NE(short_row.status().message().find("b.csv:3: expected 2 fields"), std::string::npos);
  auto text = readCsvTable(write("c.csv", "a,b\n1,zz\n"));
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.status().message().find("column 'b': not a number"), std::string::npos);
  auto missing = readCsvTable(write("d.csv", "a,b\n"), {"c"});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("missing column 'c'"), std::string::npos);
}

TEST_F(RunIo, JsonFileRoundTripAndErrors) {
  Json root = Json::object();
  root["mode"] = "dc \"quoted\"\n";
  root["n"] = 3;
  root["x"] = 0.1;
  root["nan"] = std::nan("");
  root["v"] = std::vector<double>{1, 2.5, -3e-7};
  Json nested = Json::object();
  nested["ok"] = true;
  root["agents"] = Json::array({nested, nullptr});
  const std::string back_path = dir_ + "/back.json";
  ASSERT_TRUE(writeJsonFile(back_path, root).ok());
  for (int indent : {2, -1}) {
    auto back = parseJson(root.dump(indent));
    ASSERT_TRUE(back.ok()) << back.status().message() << "\n" << root.dump(indent);
    EXPECT_EQ(back->at("mode").get<std::string>(), "dc \"quoted\"\n");
    EXPECT_DOUBLE_EQ(back->at("x").get<double>(), 0.1);
    EXPECT_TRUE(back->at("nan").is_null());
    EXPECT_DOUBLE_EQ(back->at("v").at(2).get<double>(), -3e-7);
    EXPECT_TRUE(back->at("agents").at(0).at("ok").get<bool>());
    EXPECT_EQ(back->dump(indent), root.dump(indent));
  }
  auto file = readJsonFile(back_path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->at("mode").get<std::string>(), "dc \"quoted\"\n");
  const std::string written = formatJson(root);
  EXPECT_NE(written.find("\"n\": 3,"), std::string::npos) << "integers without fraction";
  EXPECT_NE(written.find("\"v\": [1.0, 2.5, -3e-07],"), std::string::npos) << "series on one line";
  EXPECT_EQ(parseJson(written)->dump(), root.dump());
  auto bad = parseJson("{\n  \"a\": [1, 2,, 3]\n}", "f.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("f.json:2:14: "), std::string::npos)
      << bad.status().message();
  EXPECT_EQ(bad.status().message().find('\n'), std::string::npos) << "one line";
  EXPECT_FALSE(parseJson("{\"a\": 1} x").ok());
  EXPECT_FALSE(parseJson("\"open").ok());
  EXPECT_FALSE(parseJson("{\"a\" 1}").ok());
  EXPECT_EQ(parseJson("\"\\u00e9\"")->get<std::string>(), "\xc3\xa9");
  EXPECT_NE(readJsonFile(dir_ + "/none.json").status().message().find("none.json: cannot open"),
            std::string::npos);
}

TEST_F(RunIo, WriterAndReaderAgree) {
  test::FakeRunOptions o;
  o.agents = 1;
  o.steps = 20;
  test::writeFakeRun(dir_ + "/run", o);
  auto ids = listAgentIds(dir_ + "/run");
  ASSERT_TRUE(ids.ok());
  EXPECT_EQ(*ids, std::vector<int>{1});
  auto info = readRunInfo(dir_ + "/run");
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->mode, "dc");
  EXPECT_EQ(info->filter, "nhinf");
  auto run = readAgentRun(dir_ + "/run", 1);
  ASSERT_TRUE(run.ok()) << run.status().message();
  EXPECT_EQ(run->trajectory.size(), 20u);
  ASSERT_TRUE(run->ins_trajectory.has_value());
  EXPECT_EQ(run->ins_trajectory->size(), 20u);
  ASSERT_EQ(run->states.size(), 20u);
  EXPECT_TRUE(run->states_full_covariance);
  EXPECT_LT((run->states[3].P - test::fakeCovariance()).norm(), 1e-9);
  ASSERT_EQ(run->truth.size(), 20u);
  EXPECT_LT((run->truth[5].x - test::circleState(0.5, o, 1)).norm(), 1e-8);
  EXPECT_NEAR(run->trajectory[4].p_BinN.x(), run->states[4].x(0), 1e-6);
  ASSERT_EQ(run->landmarks.size(), 30u);
  EXPECT_TRUE(run->landmarks[2].truth.has_value());
  EXPECT_EQ(run->landmarks[2].id, 1002);
  ASSERT_EQ(run->stats.frames.size(), 20u);
  EXPECT_EQ(run->stats.frames[19].state_size, 9 + 3 * 19);
  EXPECT_NEAR(run->stats.frames[10].landmark_sigma_mean_m, 0.5, 1e-12);
  EXPECT_EQ(run->stats.bytes_sent, 20000);
  EXPECT_NEAR(run->stats.duration_s, 1.9, 1e-9);
}

TEST_F(RunIo, ReaderReportsBrokenFiles) {
  test::FakeRunOptions o;
  o.agents = 1;
  o.steps = 5;
  const std::string run = dir_ + "/run";
  test::writeFakeRun(run, o);
  write("run/agent_1/stats.json", "{\"frames\": {\"t_s\": [1, 2], \"time_ms\": [1]}}");
  auto r = readAgentRun(run, 1);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("frames.time_ms must be an array as long"), std::string::npos)
      << r.status().message();
  write("run/agent_1/stats.json", "{\"frames\": ");
  EXPECT_NE(readAgentRun(run, 1).status().message().find("stats.json:1:"), std::string::npos);
  fs::remove(run + "/agent_1/stats.json");
  EXPECT_NE(readAgentRun(run, 1).status().message().find("stats.json: cannot open"),
            std::string::npos);
  write("run/agent_1/states.csv", "t,x,y\n0,1,2\n");
  EXPECT_NE(readAgentRun(run, 1).status().message().find("missing column 'z'"), std::string::npos);
  EXPECT_FALSE(listAgentIds(dir_ + "/nothing").ok());
  EXPECT_FALSE(listAgentIds(dir_).ok()) << "no agent_<id> folders";
}

TEST_F(RunIo, EurocGroundTruth) {
  // Two EuRoC ground-truth rows: at rest, level, heading north; then yawed 90°, moving east.
  fs::create_directories(dir_ + "/gt/uav3/mav0/state_groundtruth_estimate0");
  const double c = std::sqrt(0.5);
  std::ofstream(dir_ + "/gt/uav3/mav0/state_groundtruth_estimate0/data.csv")
      << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
         "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x, "
         "b_w_RS_S_y, b_w_RS_S_z, b_a_RS_S_x, b_a_RS_S_y, b_a_RS_S_z\n"
      << "1000000000,1,2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n"
      << "1050000000,1,2,3," << c << ",0,0," << c << ",0,2,0,0,0,0,0,0,0\n";
  bool has_velocity = false;
  auto gt = readGroundTruth(dir_ + "/gt", 3, &has_velocity);
  ASSERT_TRUE(gt.ok()) << gt.status().message();
  ASSERT_EQ(gt->size(), 2u);
  EXPECT_TRUE(has_velocity);
  EXPECT_NEAR((*gt)[1].t, 1.05, 1e-12);
  EXPECT_NEAR((*gt)[1].x(8), M_PI / 2, 1e-9);
  EXPECT_NEAR((*gt)[1].x(3), 2.0, 1e-9) << "east velocity is forward in the body";
  EXPECT_FALSE(readGroundTruth(dir_ + "/gt", 4, &has_velocity).ok());
}

}  // namespace
}  // namespace cvslam
