#pragma once
// Where tests find the repository and the shared real data (set by tests/CMakeLists.txt;
// CVSLAM_DATA_DIR in the environment overrides the shared data folder).

#include <cstdlib>
#include <string>

namespace cvslam::test {

inline std::string sourceDir() {
  return CVSLAM_SOURCE_DIR;
}

inline std::string sharedDataDir() {
  if (const char* env = std::getenv("CVSLAM_DATA_DIR")) return env;
  return CVSLAM_SHARED_DATA_DIR;
}

}  // namespace cvslam::test
