#include "cvslam/slam/visual_slam_pipeline.h"

#include <chrono>

#include "cvslam/io/config_node.h"

namespace cvslam {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

Status VisualFrontEndOptions::load(const ConfigNode& node) {
  front_end.load(node);
  association.load(node.child("association"));
  prediction.load(node.child("prediction"));
  node.get("max_hamming_distance", max_hamming_distance);
  node.get("vocabulary", vocabulary);
  node.check(max_hamming_distance > 0.0, "max_hamming_distance", "must be > 0");
  return node.status();
}

Expected<VisualSlamPipeline> VisualSlamPipeline::create(
    const VisualFrontEndOptions& options, const StereoCamera& camera,
    std::shared_ptr<const vision::Vocabulary> vocabulary) {
  VisualFrontEndOptions o = options;
  const StereoCameraOptions& c = camera.options();
  o.front_end.stereo.focal_px = c.fx;
  o.front_end.stereo.baseline_m = c.baseline;
  const bool orb = o.front_end.detector.type == vision::DetectorType::kOrb;
  o.association.descriptor_type = orb ? vision::DescriptorType::kOrb : vision::DescriptorType::kSift;
  if (orb) o.association.max_descriptor_distance = o.max_hamming_distance;
  auto fe = vision::StereoFrontEnd::create(o.front_end, std::move(vocabulary));
  if (!fe.ok()) return fe.status();
  return VisualSlamPipeline(std::move(o), std::move(fe.value()));
}

Status VisualSlamPipeline::process(int64_t t_us, const cv::Mat& left, const cv::Mat& right,
                                   VisualInertialSlam& slam, VisualFrameResult* result) {
  VisualFrameResult& r = *result;
  r = VisualFrameResult();
  r.frame.t_us = t_us;
  if (left.empty() || right.empty()) return Status::Error("pipeline: empty image");
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    return Status::Error("pipeline: images must be 8-bit grey (CV_8UC1)");
  }
  const StereoCameraOptions& c = slam.camera().options();
  if (left.cols != c.width || left.rows != c.height) {
    return Status::Error("pipeline: image size " + std::to_string(left.cols) + "×" +
                         std::to_string(left.rows) + " differs from the camera's " +
                         std::to_string(c.width) + "×" + std::to_string(c.height));
  }

  // 1. Front end: features of both images, stereo matches → observations (type 3).
  auto t0 = std::chrono::steady_clock::now();
  if (Status s = front_end_.process(left, right, &r.frame.observations); !s.ok()) return s;
  r.front_end_ms = msSince(t0);

  // 2. Predicted observations of the map at t_us (propagates the filter to t_us).
  t0 = std::chrono::steady_clock::now();
  if (Status s = predictMapObservations(slam, t_us, o_.prediction, &predicted_); !s.ok()) {
    return s;
  }
  gated_.clear();
  for (const PredictedObservation& p : predicted_) {
    if (p.descriptor == nullptr || p.descriptor->empty()) continue;
    gated_.push_back({p.landmark_id, p.z, p.S, *p.descriptor});
  }
  r.predictions = static_cast<int>(gated_.size());

  // 3. Association by descriptor and Mahalanobis gate (type 1), fresh ids for the rest.
  if (Status s = vision::associateToMap(gated_, o_.association, &r.frame.observations,
                                        &r.association);
      !s.ok()) {
    return s;
  }
  for (StereoObservation& obs : r.frame.observations) {
    if (obs.landmark_id < 0) obs.landmark_id = next_landmark_id_++;
  }
  r.association_ms = msSince(t0);

  // 4. The filter; a fresh id that is now in the state was initialised by this frame.
  t0 = std::chrono::steady_clock::now();
  if (Status s = slam.processFrame(r.frame, &r.report); !s.ok()) return s;
  r.filter_ms = msSince(t0);
  for (std::size_t i = 0; i < r.frame.observations.size(); ++i) {
    const StereoObservation& obs = r.frame.observations[i];
    if (obs.type != ObservationType::kNew) continue;
    if (slam.state().has(VariableKey::landmark(static_cast<uint64_t>(obs.landmark_id)))) {
      r.initialised.emplace_back(i, obs.landmark_id);
    }
  }
  return Status::Ok();
}

}  // namespace cvslam
