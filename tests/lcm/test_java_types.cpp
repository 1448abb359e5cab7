// The Java side of the message set, as lcm-spy uses it: build/cvslam_lcmtypes.jar must hold
// every type, and Java must find each type by the fingerprint of a C++ encoding and decode
// it (tests/lcm/tools/SpyDecodeCheck.java runs lcm-spy's own type lookup). The spy GUI
// itself was checked by hand under xvfb-run (scripts/lcm-spy.sh).

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <string>

#include "ci_facility.h"
#include "sample_messages.h"

namespace cvslam::transport {
namespace {

std::string runCommand(const std::string& command, int& exit_status) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    exit_status = -1;
    return output;
  }
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  exit_status = pclose(pipe);
  return output;
}

template <typename Msg>
void writeSample(const std::string& dir, std::map<std::string, std::string>& files) {
  const std::vector<uint8_t> b = testing::encodedSample<Msg>();
  const std::string path = dir + "/" + Msg::getTypeName() + ".bin";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  files[path] = std::string("cvslam.") + Msg::getTypeName();
}

template <typename... Msgs>
void writeAll(::testing::Types<Msgs...>*, const std::string& dir,
              std::map<std::string, std::string>& files) {
  (writeSample<Msgs>(dir, files), ...);
}

TEST(LcmJavaTypes, SpyTypeLookupDecodesEveryCppEncoding) {
  const std::string jar = std::string(CVSLAM_BINARY_DIR) + "/cvslam_lcmtypes.jar";
  int status = 0;
  runCommand("java -version 2>/dev/null", status);
  if (status != 0 || access(jar.c_str(), R_OK) != 0 || access(CVSLAM_LCM_JAR, R_OK) != 0) {
    CVSLAM_SKIP_UNLESS_CI() << "needs java, " << CVSLAM_LCM_JAR << " and " << jar;
  }
  // The class path lcm-spy.sh would run the spy with.
  std::string classpath = runCommand(
      CVSLAM_SOURCE_DIR "/scripts/lcm-spy.sh --check --build-dir " CVSLAM_BINARY_DIR, status);
  ASSERT_EQ(status, 0) << classpath;
  while (!classpath.empty() && classpath.back() == '\n') classpath.pop_back();
  char dir_template[] = "/tmp/cvslam_java_types_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::string dir = dir_template;
  std::map<std::string, std::string> files;  // path → expected Java class
  writeAll(static_cast<testing::AllMessageTypes*>(nullptr), dir, files);

  std::string command =
      "java -cp " + classpath + " " CVSLAM_SOURCE_DIR "/tests/lcm/tools/SpyDecodeCheck.java";
  for (const auto& [path, cls] : files) command += " " + path;
  const std::string output = runCommand(command + " 2>&1", status);
  EXPECT_EQ(status, 0) << output;
  for (const auto& [path, cls] : files) {
    EXPECT_NE(output.find(path + " " + cls + " utime="), std::string::npos)
        << cls << " not decoded:\n"
        << output;
    std::remove(path.c_str());
  }
  EXPECT_EQ(output.find("UNDECODABLE"), std::string::npos) << output;
  rmdir(dir.c_str());
  EXPECT_EQ(files.size(), 14u);  // every type of lcmtypes/ but header_t
}

TEST(LcmJavaTypes, SpyScriptFindsTheJars) {
  const std::string script = std::string(CVSLAM_SOURCE_DIR) + "/scripts/lcm-spy.sh";
  int status = 0;
  const std::string output =
      runCommand(script + " --check --build-dir " CVSLAM_BINARY_DIR " 2>&1", status);
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("cvslam_lcmtypes.jar"), std::string::npos) << output;
  const std::string missing =
      runCommand(script + " --check --build-dir /nonexistent_cvslam_build 2>&1", status);
  EXPECT_NE(status, 0);
  EXPECT_NE(missing.find("cvslam_lcmtypes_jar"), std::string::npos) << missing;
}

}  // namespace
}  // namespace cvslam::transport
