#include "cvslam/slam/unknown_pose_start.h"

#include <cmath>
#include <cstdio>

#include "cvslam/geometry/euler.h"
#include "cvslam/ins/ins_propagator.h"

namespace cvslam {

namespace {

std::string format(const char* fmt, double a, double b, double c, double d) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

}  // namespace

UnknownPoseStart::UnknownPoseStart(const UnknownPoseStartOptions& options,
                                   const AgentCalibration& calibration,
                                   const InitialUncertainty& sigma,
                                   std::optional<vision::StereoFrontEnd> front_end)
    : o_(options),
      calibration_(calibration),
      sigma_(sigma),
      front_end_(std::move(front_end)),
      dynamic_(options.dynamic_init, calibration.camera, calibration.options.ins.gravity) {
  rest_tried_ = o_.mode == UnknownPoseStartMode::kDynamic;
}

bool UnknownPoseStart::wantsFrames() const {
  return !started() && !pending_ && (rest_tried_ || o_.mode == UnknownPoseStartMode::kAuto);
}

Status UnknownPoseStart::addFeatures(const StereoFrameObservations& frame) {
  ++frames_;
  return wantsFrames() ? addFrame(frame) : Status::Ok();
}

Status UnknownPoseStart::addImages(int64_t t_us, const cv::Mat& left, const cv::Mat& right) {
  ++frames_;
  if (!wantsFrames() || !front_end_) return Status::Ok();
  StereoFrameObservations frame;
  frame.t_us = t_us;
  cv::Mat l = left, r = right;
  if (calibration_.rectifier) {
    if (Status s = calibration_.rectifier->rectify(left, right, &l, &r); !s.ok()) return s;
  }
  if (Status s = front_end_->process(l, r, &frame.observations); !s.ok()) return s;
  return addFrame(frame);
}

Status UnknownPoseStart::addImu(const ImuSample& s) {
  if (started()) return Status::Ok();
  if (first_us_ < 0) first_us_ = s.t_us;
  if (pending_ && s.t_us >= pending_->t_us && last_imu_) {
    // The filter starts at the frame time: its first sample is interpolated there.
    setup_ = dynamicSetup(*pending_, sigma_, calibration_.options);
    if (last_imu_->t_us < pending_->t_us)
      imu_from_start_.push_back(interpolateImu(*last_imu_, s, pending_->t_us));
    imu_from_start_.push_back(s);
    return Status::Ok();
  }
  last_imu_ = s;
  if (o_.mode != UnknownPoseStartMode::kRest) dynamic_.addImu(s);
  if (!rest_tried_) {
    rest_imu_.push_back(s);
    const auto window_us = static_cast<int64_t>(std::llround(o_.static_init.window_s * 1e6));
    if (s.t_us - rest_imu_.front().t_us >= window_us) return tryRest();
  }
  if (rest_tried_ && !pending_ && static_cast<double>(s.t_us - first_us_) * 1e-6 > o_.give_up_s) {
    return Status::Error(
        "no start in motion within " + std::to_string(o_.give_up_s) + " s (last attempt: " +
        (last_failure_.empty() ? std::string("no frames tracked") : last_failure_) + ")");
  }
  return Status::Ok();
}

Status UnknownPoseStart::tryRest() {
  rest_tried_ = true;
  const VisualInertialSlamOptions& options = calibration_.options;
  auto rest = initializeAtRest(rest_imu_, o_.static_init, options.ins.gravity,
                               options.slam.initial_accel_bias_sigma);
  if (!rest.ok()) {
    if (o_.mode == UnknownPoseStartMode::kRest) return rest.status();
    report_ = rest.status().message() + "; initialising in motion";
    rest_imu_.clear();
    return Status::Ok();
  }
  setup_ = restSetup(*rest, sigma_, options);
  imu_from_start_.push_back(rest_imu_.back());  // the window's last sample is at the start
  report_ =
      format("started at rest at t = %.6f s (roll %.2f°, pitch %.2f°, gyro bias |b| %.4f rad/s)",
             static_cast<double>(rest->t_us) * 1e-6, rest->euler(0) * 180.0 / M_PI,
             rest->euler(1) * 180.0 / M_PI, rest->gyro_bias.norm());
  return Status::Ok();
}

Status UnknownPoseStart::addFrame(const StereoFrameObservations& frame) {
  dynamic_.addFrame(frame);
  if (!rest_tried_ || !dynamic_.ready()) return Status::Ok();
  auto d = dynamic_.solve();
  if (!d.ok()) {
    last_failure_ = d.status().message();
    return Status::Ok();
  }
  pending_ = *d;
  report_ += (report_.empty() ? "" : ": ") +
             format("started in motion at t = %.6f s (speed %.2f m/s, tilt σ %.2f°, |g| %.3f)",
                    static_cast<double>(d->t_us) * 1e-6, d->v_N.norm(),
                    d->tilt_sigma * 180.0 / M_PI, d->gravity_norm);
  return Status::Ok();
}

}  // namespace cvslam
