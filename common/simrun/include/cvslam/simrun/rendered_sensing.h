#pragma once
// Image sensing of a simulated agent (`cvslam_run --sensing images`): each camera epoch is
// rendered by the StereoRenderer at the agent's true pose (rectified pinhole stereo of the
// scenario's camera) and goes through VisualSlamPipeline (front end → map prediction →
// association → VisualInertialSlam). The renderer's per-pixel ground truth gives
//  - each created landmark's true position: the surface point seen at its left pixel in the
//    frame that initialised it (what landmarks.csv reports as true_*);
//  - the precision of stereo matching: a match is right when the true point at its left pixel
//    projects within `stereo_tolerance_px` of its right pixel;
//  - the precision of map association: a type-1 observation is right when its landmark's true
//    point projects (true pose) within `association_tolerance_px` of the observed left pixel.
// Deterministic: rendering, front end and filter are.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>

#include "cvslam/render/stereo_renderer.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/frame_sensing.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/slam/visual_slam_pipeline.h"

namespace cvslam {

struct RenderedSensingOptions {
  double stereo_tolerance_px = 2.0;       ///< max |z_R − true z_R| of a right stereo match [px]
  double association_tolerance_px = 3.0;  ///< max reprojection error of a right association [px]
};

/// Running counts and times of a RenderedSensing (sums over the frames so far).
struct RenderedSensingStats {
  long frames = 0;
  long observations = 0;
  long stereo_checked = 0;  ///< stereo matches whose left pixel shows a surface
  long stereo_correct = 0;
  double disparity_error_sum = 0.0;  ///< Σ (u_L − u_R) − f·b/z_true over correct matches [px]
  double disparity_error_sq_sum = 0.0;
  long associated = 0;          ///< type-1 observations
  long associated_checked = 0;  ///< … whose landmark has a known true position
  long associated_correct = 0;
  /// … of the checked ones, those to a landmark that is not in the filter state after the
  /// frame (archived and not re-activated): proposed by the front end, unused by the filter.
  long associated_unused_checked = 0;
  long associated_unused_correct = 0;
  /// Σ |z_L − true projection|² over correct associations [px²]: how well a keypoint is
  /// found again in another view (the filter's pixel σ should match this, per coordinate).
  double reobservation_error_sq_sum = 0.0;
  double render_ms = 0.0;
  double front_end_ms = 0.0;
  vision::FrontEndTimings front_end;  ///< front_end_ms by stage (sums)
  double association_ms = 0.0;
  double filter_ms = 0.0;

  double stereoPrecision() const;       ///< stereo_correct / stereo_checked (NaN if none)
  double associationPrecision() const;  ///< associated_correct / associated_checked
  /// Precision of the associations the filter used (to landmarks in its state).
  double usedAssociationPrecision() const;
  double disparityBias() const;  ///< mean disparity error of correct matches [px]
  double disparityRms() const;   ///< RMS disparity error of correct matches [px]
  /// RMS per pixel coordinate of the left pixel of correct associations [px].
  double reobservationRms() const;
};

class RenderedSensing : public FrameSensing {
 public:
  RenderedSensing(std::shared_ptr<const render::World> world, const StereoCamera& camera,
                  const render::RenderOptions& render, VisualSlamPipeline pipeline,
                  const RenderedSensingOptions& options = {});

  Status processFrame(const sim::SimEvent& event, VisualInertialSlam& slam,
                      FrameReport* report) override;
  bool landmarkTruth(int64_t landmark_id, Eigen::Vector3d* p_LinN) const override;
  const StereoFrameObservations& lastObservations() const override { return result_.frame; }
  void nameLandmark(int64_t landmark_id, const Eigen::Vector4d& z) override;
  const VisualFrameResult* visualResult() const override { return &result_; }

  const RenderedSensingStats& stats() const { return stats_; }
  const VisualFrameResult& lastResult() const { return result_; }
  const render::StereoRendering& lastRendering() const { return rendering_; }
  const VisualSlamPipeline& pipeline() const { return pipeline_; }

 private:
  void checkFrame(const VisualInertialSlam& slam);

  render::StereoRenderer renderer_;
  VisualSlamPipeline pipeline_;
  RenderedSensingOptions o_;
  RenderedSensingStats stats_;
  render::StereoRendering rendering_;
  VisualFrameResult result_;
  std::unordered_map<int64_t, Eigen::Vector3d> truth_;  // landmark id -> true p_LinN
};

/// A SimulatedTeamRun sensing factory (SimulatedTeamRun::SensingFactory) that gives every
/// agent a RenderedSensing of the chosen world (chooseRenderWorld; built once, shared) with the
/// scenario's renderer options, the agent's camera and its own pipeline.
Expected<std::function<Expected<std::unique_ptr<FrameSensing>>(const sim::AgentSimulator&)>>
makeRenderedSensingFactory(const RenderWorldChoice& rendering,
                           const VisualFrontEndOptions& front_end,
                           std::shared_ptr<const vision::Vocabulary> vocabulary,
                           const RenderedSensingOptions& options = {});

}  // namespace cvslam
