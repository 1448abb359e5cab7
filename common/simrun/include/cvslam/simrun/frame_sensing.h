#pragma once
// How a simulated agent's camera epoch reaches its filter (docs/run_format.md `--sensing`):
// FrameSensing turns one frame event of the simulator into a VisualInertialSlam update.
// FeatureSensing is the feature-level simulation (the observations carry the true landmark
// ids, docs/conventions.md); RenderedSensing (rendered_sensing.h) renders the images and runs the
// real front end. Each also knows the true position of the landmarks its filter created.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <unordered_map>

#include "cvslam/core/status.h"
#include "cvslam/sim/simulator.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

struct VisualFrameResult;

class FrameSensing {
 public:
  virtual ~FrameSensing() = default;
  /// Processes the frame event `event` (type kFrame) with `slam`.
  virtual Status processFrame(const sim::SimEvent& event, VisualInertialSlam& slam,
                              FrameReport* report) = 0;
  /// True position of a landmark of the filter's map; false when unknown.
  virtual bool landmarkTruth(int64_t landmark_id, Eigen::Vector3d* p_LinN) const = 0;
  /// A landmark mapped after the last frame from its observation z of that frame (the
  /// cooperation's, DcCooperation::mappedPoints): its truth is where z was observed. Feature
  /// level: nothing to do (the id is the true one).
  virtual void nameLandmark(int64_t /*landmark_id*/, const Eigen::Vector4d& /*z*/) {}
  /// The observations the last frame gave the filter (landmark ids set).
  virtual const StereoFrameObservations& lastObservations() const = 0;
  /// The image path's details of the last frame (front end, association, filter, loop query;
  /// frontend.csv), valid after each frame; null when the sensing has no image path.
  virtual const VisualFrameResult* visualResult() const { return nullptr; }
};

/// Feature-level sensing: the simulator's index is the true landmark id.
class FeatureSensing : public FrameSensing {
 public:
  /// `landmarks`: the simulated world's landmarks (id = index), kept alive by the caller.
  explicit FeatureSensing(const std::vector<sim::Landmark>* landmarks) : landmarks_(landmarks) {}
  Status processFrame(const sim::SimEvent& event, VisualInertialSlam& slam,
                      FrameReport* report) override;
  bool landmarkTruth(int64_t landmark_id, Eigen::Vector3d* p_LinN) const override;
  const StereoFrameObservations& lastObservations() const override { return frame_; }

 private:
  const std::vector<sim::Landmark>* landmarks_;
  StereoFrameObservations frame_;  // reused
};

}  // namespace cvslam
