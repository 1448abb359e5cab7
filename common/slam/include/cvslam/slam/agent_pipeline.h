#pragma once
// One agent's VSLAM fed message by message (docs/architecture.md): the core of cvslam_agent and
// of each UAV in cvslam_run (SimulatedTeamRun), so that a lockstep multi-process run and the
// in-process run do exactly the same per agent. No transport, no simulation.
//
// Per agent it owns the filter (VisualInertialSlam), INS dead reckoning of the same IMU data
// for comparison (thesis §5.9: "INS only"), and optionally the image path (VisualSlamPipeline:
// front end → map prediction → association → filter) with the stereo rectifier for raw
// images. Inputs, in dataset-time order (at equal times: IMU, then the frame):
//   addImu(sample)                   propagate (lazily) and dead-reckon
//   processFeatures(frame)           feature-level observations carrying true landmark ids
//   processImages(t, left, right)    a stereo pair through the real front end
//   processWith(t, fn)               any other sensing (cvslam_run's rendered sensing)
// After each frame, lastFrame() says what it did: observations given to the filter (for the
// cooperation, dc_cooperation.h), FrameReport, and the agent's own processing time.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>

#include <opencv2/core.hpp>

#include "cvslam/core/status.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/slam/agent_setup.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "cvslam/slam/visual_slam_pipeline.h"
#include "cvslam/vision/stereo_rectifier.h"

namespace cvslam {

/// What the last processed frame did.
struct AgentFrame {
  int64_t t_us = 0;
  FrameReport report;
  /// Observations as given to the filter (landmark ids set): what the cooperation sees.
  const StereoFrameObservations* observations = nullptr;
  /// Image path only: front end, association and filter details; null for features.
  const VisualFrameResult* visual = nullptr;
  /// The agent's own work on the frame [ms]: features: processFrame; images: front end +
  /// association + filter (rectification included, rendering in cvslam_run excluded).
  double time_ms = 0.0;
};

class AgentPipeline {
 public:
  using FrameFunction = std::function<Status(VisualInertialSlam&, FrameReport*)>;

  /// Builds the filter with setup.options and the camera and initialises it with setup.
  static Expected<std::unique_ptr<AgentPipeline>> create(int agent_id,
                                                         const AgentFilterSetup& setup,
                                                         const StereoCamera& camera);

  /// Enables processImages with this image path; `rectifier` (optional) undistorts and
  /// rectifies raw pairs first (real cameras), its rectified model being `camera`.
  void useImages(VisualSlamPipeline pipeline,
                 std::optional<vision::StereoRectifier> rectifier = std::nullopt);
  bool imagesEnabled() const { return visual_ != nullptr; }

  /// Buffers the sample in the filter and advances the dead reckoning.
  Status addImu(const ImuSample& sample);
  /// A frame of feature-level observations whose index is the true landmark id.
  Status processFeatures(const StereoFrameObservations& frame);
  /// A stereo pair (CV_8UC1) taken at t_us.
  Status processImages(int64_t t_us, const cv::Mat& left, const cv::Mat& right);
  /// A frame processed by `fn` with the filter (cvslam_run's FrameSensing); time_ms is the
  /// wall time of fn unless `time_ms` is given afterwards by setLastFrameTime.
  Status processWith(int64_t t_us, const FrameFunction& fn,
                     const StereoFrameObservations* observations = nullptr,
                     const VisualFrameResult* visual = nullptr);
  void setLastFrameTime(double ms) { last_.time_ms = ms; }

  int id() const { return id_; }
  VisualInertialSlam& slam() { return slam_; }
  const VisualInertialSlam& slam() const { return slam_; }
  /// INS-only state (9 or 15 entries, Euler layout) after the last IMU sample.
  const Eigen::VectorXd& insState() const { return x_ins_euler_; }
  const AgentFrame& lastFrame() const { return last_; }
  long frames() const { return frames_; }

 private:
  AgentPipeline(int agent_id, const AgentFilterSetup& setup, const StereoCamera& camera);

  int id_;
  VisualInertialSlam slam_;
  InsPropagator dead_reckoning_;
  Eigen::VectorXd x_ins_;        // the propagator's own parametrisation (ins.attitude)
  Eigen::Quaterniond q_ins_;     // its nominal rotation (error state)
  Eigen::VectorXd x_ins_euler_;  // x_ins_ in the Euler layout (insState)
  ImuSample last_imu_;
  bool have_imu_ = false;
  std::unique_ptr<VisualSlamPipeline> visual_;
  std::optional<vision::StereoRectifier> rectifier_;
  cv::Mat left_rect_, right_rect_;
  StereoFrameObservations feature_frame_;  // reused
  VisualFrameResult visual_result_;
  AgentFrame last_;
  long frames_ = 0;
};

/// Feature-level sensing (docs/conventions.md): the index is the true landmark id, so it names the
/// observation's landmark. Shared by FeatureSensing and AgentPipeline::processFeatures.
void useTrueLandmarkIds(StereoFrameObservations* frame);

}  // namespace cvslam
