#pragma once
// Command line of cvslam_replay (kept apart from the publishing loop).
#include <optional>
#include <string>
#include <vector>
#include "cvslam/lcm/lcm_bus.h"

namespace cvslam::replay {

extern const char* const kUsage;

struct DatasetArg {
  int id = 0;
  std::string path;
};

struct Args {
  std::string scenario;
  std::vector<DatasetArg> datasets;
  std::string log;          ///< an LCM log (lcm-logger) whose sensor channels are played
  std::vector<int> agents;  ///< play only these UAVs (empty: all)
  double start_at = 0.0;    ///< > 0: wait until this wall time (Unix seconds) to begin
  double rate = 1.0;        ///< play speed; 0 = as fast as possible
  bool lockstep = false;
  std::vector<int> participants;   ///< lockstep participants; empty = the replayed agents
  double lockstep_timeout = 60.0;  ///< [s]
  std::string lcm_url = transport::kDefaultLcmUrl;
  double duration = 0.0;  ///< ≤ 0: everything
  double start = 0.0;
  /// Folders: the camera clock's offset to the IMU's [s]: a frame stamped t was taken at
  /// IMU time t + offset (Kalibr's timeshift_cam_imu); frames are played at that time.
  double camera_time_offset = 0.0;
  bool compress = false;
  bool no_gt = false;
  std::string sensing = "images";  ///< scenario: images | features
  std::string world;               ///< scenario: aerial | hall | "" (choose)
  long long seed = -1;
  bool quiet = false;
};

/// Fills `args` from the command line. Returns nullopt when the program should go on;
/// otherwise the exit status main should return (0 after --help; 2 after an error, whose
/// one line "cvslam_replay: …" is printed).
std::optional<int> parseArgs(int argc, char** argv, Args& args);

}  // namespace cvslam::replay
