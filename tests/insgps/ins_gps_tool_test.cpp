// cvslam_ins_gps as a process: bad input gives one line on stderr and a non-zero exit; a run
// writes the tables and one CSV per filter with estimate, truth and 1σ columns.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;

struct Result {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Result runTool(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = std::string(CVSLAM_INS_GPS_EXE) + " " + args + " > '" + out.string() +
                          "' 2> '" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  Result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

fs::path freshDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("cvslam_insgps_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(InsGpsTool, BadInputGivesOneLineAndNonZeroExit) {
  const fs::path dir = freshDir("bad");
  const char* configs[] = {"duration_s: -1\n", "filters: {run: [ekf, pf]}\n", "typo: 1\n",
                           "gps: {outages: [{start_s: 5, end_s: 1}]}\n"};
  for (const char* text : configs) {
    std::ofstream(dir / "bad.yaml") << text;
    const Result r = runTool("--config '" + (dir / "bad.yaml").string() + "'", dir);
    EXPECT_NE(r.exit_code, 0) << text;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("cvslam_ins_gps: ", 0), 0u) << r.err;
  }
  const Result missing = runTool("--config /nonexistent/flight.yaml", dir);
  EXPECT_NE(missing.exit_code, 0);
  const Result no_config = runTool("", dir);
  EXPECT_NE(no_config.exit_code, 0);
}

TEST(InsGpsTool, WritesTablesAndOneCsvPerFilter) {
  const fs::path dir = freshDir("run");
  std::ofstream(dir / "short.yaml") << R"(
seed: 3
duration_s: 6.0
trajectory: {kind: circle, radius: 30.0, altitude: 20.0, speed: 8.0}
imu: {rate_hz: 100.0, gyro_random_walk: 0.0, accel_random_walk: 0.0}
gps: {rate_hz: 2.0}
filters: {run: [ekf, sdre]}
)";
  const Result r = runTool("--config '" + (dir / "short.yaml").string() + "' --out '" +
                               (dir / "out").string() + "' --csv-every 10",
                           dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| ekf |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| sdre |"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir / "out" / "tables.md"));
  EXPECT_TRUE(fs::exists(dir / "out" / "gps.csv"));
  EXPECT_FALSE(fs::exists(dir / "out" / "ukf.csv"));
  for (const char* name : {"ekf", "sdre"}) {
    std::ifstream in(dir / "out" / (std::string(name) + ".csv"));
    std::string header, line;
    ASSERT_TRUE(std::getline(in, header)) << name;
    EXPECT_EQ(header.rfind("t,x,y,z,u,v,w,phi,theta,psi,x_true", 0), 0u) << header;
    int rows = 0;
    while (std::getline(in, line)) ++rows;
    EXPECT_EQ(rows, 61) << name;  // 601 samples at 100 Hz, every 10th
  }
}

}  // namespace
