#pragma once
// One agent's sensor stream from an EuRoC ASL folder (EurocDataset): IMU, ground truth (if
// the folder has it) and stereo images, in the order of sensor_stream.h. Images are decoded
// one frame at a time as the stream reaches them. Play time is dataset time minus the
// folder's first timestamp (IMU, frame or ground truth), so folders recorded at different
// times play on one clock; our simulated folders start at 0 and keep their times.
// When a frame is handed out, the next one is decoded on another thread (std::async), so
// that PNG decoding overlaps publishing: 752×480 pairs cost ~30 ms to decode.
#include <future>
#include <memory>
#include <string>
#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/sensors/sensor_stream.h"

namespace cvslam {

class EurocSensorStream final : public AgentSensorStream {
 public:
  /// Opens the folder (errors from EurocDataset::open name the file). Events before
  /// `start_s` of play time are skipped without decoding images. `camera_offset_us`: a frame
  /// stamped t was taken at IMU time t + camera_offset_us (a constant camera–IMU clock offset);
  /// frames are handed out, ordered and stamped at the corrected time.
  static Expected<std::unique_ptr<EurocSensorStream>> open(int agent_id, const std::string& path,
                                                           double start_s = 0.0,
                                                           int64_t camera_offset_us = 0);
  int agentId() const override { return agent_id_; }
  bool next(SensorEvent& event) override;
  const Status& status() const override { return status_; }
  int64_t endPlayUs() const override { return end_play_us_; }
  int64_t offsetUs() const { return offset_us_; }
  const EurocDataset& dataset() const { return dataset_; }

 private:
  EurocSensorStream(int agent_id, EurocDataset dataset);
  int agent_id_;
  EurocDataset dataset_;
  int64_t offset_us_ = 0;
  int64_t camera_offset_us_ = 0;  // added to every frame stamp
  int64_t end_play_us_ = 0;
  std::size_t next_imu_ = 0, next_gt_ = 0, next_frame_ = 0;
  Status status_;
  /// Decoding of frame next_frame_ when valid; declared last so that it is destroyed (and
  /// waited for) before the dataset it reads.
  std::future<Expected<EurocStereoFrame>> prefetch_;
};

}  // namespace cvslam
