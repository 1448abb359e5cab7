#include "cvslam/slam/agent_pipeline.h"

#include <chrono>

namespace cvslam {
namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void useTrueLandmarkIds(StereoFrameObservations* frame) {
  for (StereoObservation& obs : frame->observations) obs.landmark_id = obs.index;
}

AgentPipeline::AgentPipeline(int agent_id, const AgentFilterSetup& setup,
                             const StereoCamera& camera)
    : id_(agent_id), slam_(setup.options, camera), dead_reckoning_(setup.options.ins) {
  dead_reckoning_.fromEulerLayout(setup.x0, &x_ins_, &q_ins_);
  if (setup.q0_BtoN) q_ins_ = *setup.q0_BtoN;
  x_ins_euler_ = dead_reckoning_.eulerLayout(x_ins_, q_ins_);
}

Expected<std::unique_ptr<AgentPipeline>> AgentPipeline::create(int agent_id,
                                                               const AgentFilterSetup& setup,
                                                               const StereoCamera& camera) {
  if (auto p = setup.options.filter.policy(); !p.ok()) return p.status();
  std::unique_ptr<AgentPipeline> a(new AgentPipeline(agent_id, setup, camera));
  const Status init = setup.q0_BtoN
                          ? a->slam_.initialize(setup.t0_us, setup.x0, *setup.q0_BtoN, setup.P0)
                          : a->slam_.initialize(setup.t0_us, setup.x0, setup.P0);
  if (Status s = init; !s.ok()) {
    return Status::Error("agent " + std::to_string(agent_id) + ": " + s.message());
  }
  return a;
}

void AgentPipeline::useImages(VisualSlamPipeline pipeline,
                              std::optional<vision::StereoRectifier> rectifier) {
  visual_ = std::make_unique<VisualSlamPipeline>(std::move(pipeline));
  rectifier_ = std::move(rectifier);
}

Status AgentPipeline::addImu(const ImuSample& sample) {
  if (Status s = slam_.addImu(sample); !s.ok()) return s;
  if (have_imu_) {
    x_ins_ = dead_reckoning_.stepMean(x_ins_, q_ins_, last_imu_, sample,
                                      Eigen::VectorXd::Zero(dead_reckoning_.noiseSize()), &q_ins_);
    x_ins_euler_ = dead_reckoning_.eulerLayout(x_ins_, q_ins_);
  }
  last_imu_ = sample;
  have_imu_ = true;
  return Status::Ok();
}

Status AgentPipeline::processWith(int64_t t_us, const FrameFunction& fn,
                                  const StereoFrameObservations* observations,
                                  const VisualFrameResult* visual) {
  const auto t0 = std::chrono::steady_clock::now();
  FrameReport report;
  if (Status s = fn(slam_, &report); !s.ok()) {
    return Status::Error("agent " + std::to_string(id_) + " at t = " +
                         std::to_string(static_cast<double>(t_us) * 1e-6) + " s: " + s.message());
  }
  last_.t_us = t_us;
  last_.report = report;
  last_.observations = observations;
  last_.visual = visual;
  last_.time_ms = msSince(t0);
  ++frames_;
  return Status::Ok();
}

Status AgentPipeline::processFeatures(const StereoFrameObservations& frame) {
  feature_frame_ = frame;
  useTrueLandmarkIds(&feature_frame_);
  return processWith(
      frame.t_us,
      [this](VisualInertialSlam& slam, FrameReport* report) {
        return slam.processFrame(feature_frame_, report);
      },
      &feature_frame_);
}

Status AgentPipeline::processImages(int64_t t_us, const cv::Mat& left, const cv::Mat& right) {
  if (!visual_) return Status::Error("agent " + std::to_string(id_) + ": images not enabled");
  double rectify_ms = 0.0;
  const cv::Mat* l = &left;
  const cv::Mat* r = &right;
  if (rectifier_) {
    const auto t0 = std::chrono::steady_clock::now();
    if (Status s = rectifier_->rectify(left, right, &left_rect_, &right_rect_); !s.ok()) return s;
    rectify_ms = msSince(t0);
    l = &left_rect_;
    r = &right_rect_;
  }
  Status s = processWith(
      t_us,
      [&](VisualInertialSlam& slam, FrameReport* report) {
        if (Status p = visual_->process(t_us, *l, *r, slam, &visual_result_); !p.ok()) return p;
        *report = visual_result_.report;
        return Status::Ok();
      },
      &visual_result_.frame, &visual_result_);
  if (!s.ok()) return s;
  // The same frame time as cvslam_run's image sensing reports (rendering excluded there).
  last_.time_ms = rectify_ms + visual_result_.front_end_ms + visual_result_.association_ms +
                  visual_result_.filter_ms;
  return Status::Ok();
}

}  // namespace cvslam
