#include "cvslam/simrun/rendered_sensing.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

namespace cvslam {

namespace {

/// Pixel of a point in N in a rendered camera image; empty behind the camera.
std::optional<Eigen::Vector2d> projectInto(const render::RenderedImage& image,
                                           const Eigen::Vector3d& p_N) {
  const Eigen::Vector3d p_C = image.R_NtoC * (p_N - image.p_CinN);
  if (p_C.z() <= 1e-9) return std::nullopt;
  const render::PinholeIntrinsics& k = image.intrinsics;
  return Eigen::Vector2d(k.fx * p_C.x() / p_C.z() + k.cx, k.fy * p_C.y() / p_C.z() + k.cy);
}

double ratio(long num, long den) {
  return den > 0 ? static_cast<double>(num) / static_cast<double>(den)
                 : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

double RenderedSensingStats::stereoPrecision() const {
  return ratio(stereo_correct, stereo_checked);
}

double RenderedSensingStats::associationPrecision() const {
  return ratio(associated_correct, associated_checked);
}

double RenderedSensingStats::usedAssociationPrecision() const {
  return ratio(associated_correct - associated_unused_correct,
               associated_checked - associated_unused_checked);
}

double RenderedSensingStats::disparityBias() const {
  return stereo_correct > 0 ? disparity_error_sum / static_cast<double>(stereo_correct)
                            : std::numeric_limits<double>::quiet_NaN();
}

double RenderedSensingStats::reobservationRms() const {
  return associated_correct > 0 ? std::sqrt(reobservation_error_sq_sum /
                                            (2.0 * static_cast<double>(associated_correct)))
                                : std::numeric_limits<double>::quiet_NaN();
}

double RenderedSensingStats::disparityRms() const {
  return stereo_correct > 0
             ? std::sqrt(disparity_error_sq_sum / static_cast<double>(stereo_correct))
             : std::numeric_limits<double>::quiet_NaN();
}

RenderedSensing::RenderedSensing(std::shared_ptr<const render::World> world,
                                 const StereoCamera& camera, const render::RenderOptions& render,
                                 VisualSlamPipeline pipeline, const RenderedSensingOptions& options)
    : renderer_(std::move(world), camera, render), pipeline_(std::move(pipeline)), o_(options) {}

Status RenderedSensing::processFrame(const sim::SimEvent& event, VisualInertialSlam& slam,
                                     FrameReport* report) {
  // Render at the true pose (the simulated camera), then the agent's own image path.
  const auto t0 = std::chrono::steady_clock::now();
  rendering_ = renderer_.render(event.truth.p_BinN, event.truth.euler,
                                render::StereoRenderer::frameIndexAt(event.t_us));
  stats_.render_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (Status s = pipeline_.process(event.t_us, rendering_.left.image, rendering_.right.image, slam,
                                   &result_);
      !s.ok()) {
    return s;
  }
  if (report != nullptr) *report = result_.report;
  ++stats_.frames;
  stats_.observations += static_cast<long>(result_.frame.observations.size());
  stats_.front_end_ms += result_.front_end_ms;
  stats_.front_end.detect_ms += result_.front_end.detect_ms;
  stats_.front_end.stereo_ms += result_.front_end.stereo_ms;
  stats_.front_end.describe_ms += result_.front_end.describe_ms;
  stats_.front_end.index_ms += result_.front_end.index_ms;
  stats_.association_ms += result_.association_ms;
  stats_.filter_ms += result_.filter_ms;
  checkFrame(slam);
  return Status::Ok();
}

void RenderedSensing::checkFrame(const VisualInertialSlam& slam) {
  const std::vector<StereoObservation>& obs = result_.frame.observations;
  // Stereo matches against the renderer's ground truth.
  for (const StereoObservation& o : obs) {
    const std::optional<render::SurfacePoint> s = rendering_.left.surfaceAt(o.z(0), o.z(1));
    if (!s) continue;
    const std::optional<Eigen::Vector2d> right = projectInto(rendering_.right, s->p_N);
    ++stats_.stereo_checked;
    if (right && (*right - o.z.tail<2>()).norm() <= o_.stereo_tolerance_px) {
      ++stats_.stereo_correct;
      const render::PinholeIntrinsics& k = rendering_.left.intrinsics;
      const double baseline = (rendering_.right.p_CinN - rendering_.left.p_CinN).norm();
      const double e = (o.z(0) - o.z(2)) - k.fx * baseline / s->depth;
      stats_.disparity_error_sum += e;
      stats_.disparity_error_sq_sum += e * e;
    }
  }
  // Map associations: the landmark's true point must be where it was observed.
  for (const StereoObservation& o : obs) {
    if (o.type != ObservationType::kReobserved) continue;
    ++stats_.associated;
    auto it = truth_.find(o.landmark_id);
    if (it == truth_.end()) continue;
    ++stats_.associated_checked;
    const bool used = slam.state().has(VariableKey::landmark(static_cast<uint64_t>(o.landmark_id)));
    if (!used) ++stats_.associated_unused_checked;
    const std::optional<Eigen::Vector2d> left = projectInto(rendering_.left, it->second);
    if (left && (*left - o.z.head<2>()).norm() <= o_.association_tolerance_px) {
      ++stats_.associated_correct;
      if (!used) ++stats_.associated_unused_correct;
      stats_.reobservation_error_sq_sum += (*left - o.z.head<2>()).squaredNorm();
    }
  }
  // Ground truth of the landmarks this frame created: the surface at their left pixel (those the
  // cooperation maps after the frame are named by nameLandmark).
  for (const auto& [i, id] : result_.initialised) nameLandmark(id, obs[i].z);
}

void RenderedSensing::nameLandmark(int64_t landmark_id, const Eigen::Vector4d& z) {
  if (const std::optional<render::SurfacePoint> s = rendering_.left.surfaceAt(z(0), z(1)))
    truth_[landmark_id] = s->p_N;
}

bool RenderedSensing::landmarkTruth(int64_t landmark_id, Eigen::Vector3d* p_LinN) const {
  auto it = truth_.find(landmark_id);
  if (it == truth_.end()) return false;
  *p_LinN = it->second;
  return true;
}

Expected<std::function<Expected<std::unique_ptr<FrameSensing>>(const sim::AgentSimulator&)>>
makeRenderedSensingFactory(const RenderWorldChoice& rendering,
                           const VisualFrontEndOptions& front_end,
                           std::shared_ptr<const vision::Vocabulary> vocabulary,
                           const RenderedSensingOptions& options) {
  auto created = render::World::create(rendering.options);
  if (!created.ok()) return created.status();
  std::shared_ptr<const render::World> shared = *created;
  const render::RenderOptions render = rendering.render;
  return std::function<Expected<std::unique_ptr<FrameSensing>>(const sim::AgentSimulator&)>(
      [shared, render, front_end, vocabulary,
       options](const sim::AgentSimulator& agent) -> Expected<std::unique_ptr<FrameSensing>> {
        auto pipeline = VisualSlamPipeline::create(front_end, agent.camera(), vocabulary);
        if (!pipeline.ok()) return pipeline.status();
        return std::unique_ptr<FrameSensing>(std::make_unique<RenderedSensing>(
            shared, agent.camera(), render, std::move(pipeline.value()), options));
      });
}

}  // namespace cvslam
