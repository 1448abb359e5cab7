#include "cvslam/sensors/euroc_sensor_stream.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cvslam/geometry/euler.h"

namespace cvslam {
namespace {

// EuRoC stores nanoseconds; messages carry microseconds (docs/architecture.md).
int64_t nsToUs(int64_t t_ns) {
  return t_ns >= 0 ? (t_ns + 500) / 1000 : -((-t_ns + 500) / 1000);
}

constexpr int64_t kNone = std::numeric_limits<int64_t>::max();

}  // namespace

EurocSensorStream::EurocSensorStream(int agent_id, EurocDataset dataset)
    : agent_id_(agent_id), dataset_(std::move(dataset)) {}

Expected<std::unique_ptr<EurocSensorStream>> EurocSensorStream::open(int agent_id,
                                                                     const std::string& path,
                                                                     double start_s,
                                                                     int64_t camera_offset_us) {
  auto dataset = EurocDataset::open(path);
  if (!dataset.ok()) return dataset.status();
  std::unique_ptr<EurocSensorStream> s(new EurocSensorStream(agent_id, std::move(*dataset)));
  const EurocDataset& d = s->dataset_;
  s->camera_offset_us_ = camera_offset_us;
  auto frameUs = [&](std::size_t i) { return nsToUs(d.frameTimeNs(i)) + camera_offset_us; };
  int64_t first = kNone, last = std::numeric_limits<int64_t>::min();
  auto extend = [&](int64_t t_us) {
    first = std::min(first, t_us);
    last = std::max(last, t_us);
  };
  if (!d.imu().empty()) extend(d.imu().front().t_us), extend(d.imu().back().t_us);
  if (d.frameCount() > 0) extend(frameUs(0)), extend(frameUs(d.frameCount() - 1));
  if (d.hasGroundTruth())
    extend(nsToUs(d.groundTruth().front().t_ns)), extend(nsToUs(d.groundTruth().back().t_ns));
  if (first == kNone) return Status::Error(d.mav0() + ": no IMU samples, frames or ground truth");
  s->offset_us_ = first;
  s->end_play_us_ = last - first;
  const int64_t start_us = first + std::llround(start_s * 1e6);
  while (s->next_imu_ < d.imu().size() && d.imu()[s->next_imu_].t_us < start_us) ++s->next_imu_;
  while (s->next_gt_ < d.groundTruth().size() &&
         nsToUs(d.groundTruth()[s->next_gt_].t_ns) < start_us)
    ++s->next_gt_;
  while (s->next_frame_ < d.frameCount() && frameUs(s->next_frame_) < start_us) ++s->next_frame_;
  return s;
}

bool EurocSensorStream::next(SensorEvent& event) {
  if (!status_.ok()) return false;
  const int64_t t_imu = next_imu_ < dataset_.imu().size() ? dataset_.imu()[next_imu_].t_us : kNone;
  const int64_t t_gt = next_gt_ < dataset_.groundTruth().size()
                           ? nsToUs(dataset_.groundTruth()[next_gt_].t_ns)
                           : kNone;
  const int64_t t_frame = next_frame_ < dataset_.frameCount()
                              ? nsToUs(dataset_.frameTimeNs(next_frame_)) + camera_offset_us_
                              : kNone;
  const int64_t t = std::min({t_imu, t_gt, t_frame});
  if (t == kNone) return false;
  event = SensorEvent();
  event.agent_id = agent_id_;
  event.t_us = t;
  event.play_us = t - offset_us_;
  if (t_imu == t) {  // IMU first at ties, then ground truth, then the frame
    event.type = SensorEventType::kImu;
    event.imu = dataset_.imu()[next_imu_++];
  } else if (t_gt == t) {
    const EurocGroundTruth& g = dataset_.groundTruth()[next_gt_++];
    event.type = SensorEventType::kGroundTruth;
    event.truth.p_BinN = g.p_SinR;
    event.truth.q_BtoN = g.q_StoR.normalized();
    event.truth.euler =
        eulerFromRotationNavToBody(event.truth.q_BtoN.toRotationMatrix().transpose());
    event.truth.v_N = g.v_SinR;
    event.truth.gyro_bias = g.gyro_bias;
    event.truth.accel_bias = g.accel_bias;
  } else {
    Expected<EurocStereoFrame> frame =
        prefetch_.valid() ? prefetch_.get() : dataset_.loadFrame(next_frame_);
    ++next_frame_;
    if (frame.ok() && next_frame_ < dataset_.frameCount()) {
      const std::size_t i = next_frame_;
      prefetch_ = std::async(std::launch::async, [this, i] { return dataset_.loadFrame(i); });
    }
    if (!frame.ok()) {
      status_ = frame.status();
      return false;
    }
    event.type = SensorEventType::kStereoImage;
    event.left = frame->left;
    event.right = frame->right;
  }
  return true;
}

}  // namespace cvslam
