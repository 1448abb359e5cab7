#pragma once
// How an agent starts without ground truth (cvslam_agent `agent.start: rest | dynamic |
// auto`; issue: real recordings). Fed the agent's sensor events until it can start, it gives
// the filter setup and the IMU samples to hand the filter from the start time on.
//   rest     static initialisation from the first window_s of IMU (ins/static_initializer.h);
//            a vehicle not at rest is an error.
//   dynamic  initialisation in motion from the first frames and the IMU
//            (slam/dynamic_initializer.h), retried with a sliding window until it succeeds or
//            give_up_s has passed.
//   auto     rest if the first window is a rest, otherwise dynamic (the default of
//            scripts/run_dataset.sh): real recordings start either way.
// Frames reach the dynamic initialiser as feature-level observations, or as raw / rectified
// images through the agent's own front end (and rectifier for raw cameras).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include "cvslam/core/status.h"
#include "cvslam/ins/initial_uncertainty.h"
#include "cvslam/ins/static_initializer.h"

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/slam/agent_calibration.h"
#include "cvslam/slam/agent_setup.h"
#include "cvslam/slam/dynamic_initializer.h"
#include "cvslam/vision/stereo_front_end.h"

namespace cvslam {

enum class UnknownPoseStartMode : uint8_t { kRest, kDynamic, kAuto };

struct UnknownPoseStartOptions {
  UnknownPoseStartMode mode = UnknownPoseStartMode::kAuto;
  StaticInitializerOptions static_init;    ///< `static_init`
  DynamicInitializerOptions dynamic_init;  ///< `dynamic_init`
  /// Dynamic: no start this long after the first sample is an error [s].
  double give_up_s = 30.0;
};

class UnknownPoseStart {
 public:
  /// `front_end` is needed for image frames (none: image frames are ignored until the start).
  UnknownPoseStart(const UnknownPoseStartOptions& options, const AgentCalibration& calibration,
                   const InitialUncertainty& sigma,
                   std::optional<vision::StereoFrontEnd> front_end);

  /// The sensor data before the start, in time order. Fail with one line when the agent
  /// cannot start (rest mode not at rest, dynamic mode given up).
  Status addImu(const ImuSample& sample);
  Status addFeatures(const StereoFrameObservations& frame);
  Status addImages(int64_t t_us, const cv::Mat& left, const cv::Mat& right);
  bool started() const { return setup_.has_value(); }
  /// Once started: the filter setup (t0_us = the start time).
  const AgentFilterSetup& setup() const { return *setup_; }
  /// Once started: the IMU samples to give the filter, the first one at t0_us.
  const std::vector<ImuSample>& imuFromStart() const { return imu_from_start_; }
  /// One line: how the agent started (for the log).
  const std::string& report() const { return report_; }
  /// Frames seen before the start.
  long framesBeforeStart() const { return frames_; }

 private:
  bool wantsFrames() const;
  /// A frame's observations to the dynamic initialiser (when it is in use).
  Status addFrame(const StereoFrameObservations& frame);
  /// Rest window full: start at rest, or (auto) go on in motion.
  Status tryRest();

  UnknownPoseStartOptions o_;
  const AgentCalibration& calibration_;
  InitialUncertainty sigma_;
  std::optional<vision::StereoFrontEnd> front_end_;
  DynamicInitializer dynamic_;
  bool rest_tried_ = false;
  std::vector<ImuSample> rest_imu_;
  std::optional<DynamicInitialization> pending_;  // solved, waiting for the IMU to pass t_us
  std::string last_failure_;
  std::optional<ImuSample> last_imu_;
  int64_t first_us_ = -1;
  long frames_ = 0;
  std::optional<AgentFilterSetup> setup_;
  std::vector<ImuSample> imu_from_start_;
  std::string report_;
};

}  // namespace cvslam
