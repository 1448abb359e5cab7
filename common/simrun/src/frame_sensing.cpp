#include "cvslam/simrun/frame_sensing.h"

#include "cvslam/slam/agent_pipeline.h"

namespace cvslam {

Status FeatureSensing::processFrame(const sim::SimEvent& event, VisualInertialSlam& slam,
                                    FrameReport* report) {
  frame_ = event.frame;
  // Feature-level sensing: the simulator's index is the true landmark id (docs/conventions.md).
  useTrueLandmarkIds(&frame_);
  return slam.processFrame(frame_, report);
}

bool FeatureSensing::landmarkTruth(int64_t landmark_id, Eigen::Vector3d* p_LinN) const {
  if (landmarks_ == nullptr || landmark_id < 0 ||
      landmark_id >= static_cast<int64_t>(landmarks_->size())) {
    return false;
  }
  *p_LinN = (*landmarks_)[static_cast<std::size_t>(landmark_id)].p_LinN;
  return true;
}

}  // namespace cvslam
