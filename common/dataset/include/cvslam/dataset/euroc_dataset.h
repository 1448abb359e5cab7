#pragma once
// Reader for EuRoC ASL folders (Burri et al., IJRR 2016), docs/run_format.md:
//   <root>/mav0/cam0/data.csv + data/<t_ns>.png, cam1 alike, imu0/data.csv,
//   state_groundtruth_estimate0/data.csv (optional), */sensor.yaml (optional).
//
// open() reads the CSV lists, the IMU and the ground truth, pairs stereo frames by exact
// timestamp (cam1 may list extra frames: they are counted, not paired) and checks every paired
// PNG's header (exists, is a PNG, has the expected size: the sensor.yaml resolution, else the
// first image's). Images are decoded only by loadFrame(), one frame at a time.
// Every error is one line naming the file (and line), e.g.
//   ".../mav0/imu0/data.csv:17: expected 7 comma-separated fields, got 6".
//
// Frames: values are passed through as recorded. EuRoC's IMU frame S is its body frame; its
// ground truth is the pose of S in the world frame R (z up); converting to NED/FRD is the
// caller's business (see render/world.h for the hall's W → N convention).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/dataset/euroc_sensor_yaml.h"

namespace cvslam {

/// One row of state_groundtruth_estimate0/data.csv.
struct EurocGroundTruth {
  int64_t t_ns = 0;
  Eigen::Vector3d p_SinR = Eigen::Vector3d::Zero();            ///< position [m]
  Eigen::Quaterniond q_StoR = Eigen::Quaterniond::Identity();  ///< orientation (w x y z)
  Eigen::Vector3d v_SinR = Eigen::Vector3d::Zero();            ///< velocity [m/s]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();         ///< b_w [rad/s]
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();        ///< b_a [m/s²]
};

struct EurocStereoFrame {
  int64_t t_ns = 0;
  cv::Mat left, right;  ///< CV_8UC1 as stored
};

class EurocDataset {
 public:
  /// `path` is the folder that holds mav0/ (or mav0 itself).
  static Expected<EurocDataset> open(const std::string& path);

  std::size_t frameCount() const { return frames_.size(); }
  int64_t frameTimeNs(std::size_t i) const { return frames_[i].t_ns; }
  /// Decodes both images of frame i (checks they decode and have the expected size).
  Expected<EurocStereoFrame> loadFrame(std::size_t i) const;

  /// cam0 / cam1 entries without a partner of the same timestamp.
  int unpairedLeft() const { return unpaired_left_; }
  int unpairedRight() const { return unpaired_right_; }
  cv::Size imageSize() const { return image_size_; }

  /// IMU samples in time order (t_us rounded from ns).
  const std::vector<ImuSample>& imu() const { return imu_; }
  /// Raw nanosecond timestamps of imu() (same order).
  const std::vector<int64_t>& imuTimesNs() const { return imu_t_ns_; }
  /// Ground truth in time order; empty when the folder has none.
  const std::vector<EurocGroundTruth>& groundTruth() const { return ground_truth_; }
  bool hasGroundTruth() const { return !ground_truth_.empty(); }

  /// Calibrations from sensor.yaml when present and readable.
  const std::optional<EurocCameraInfo>& cam0Info() const { return cam0_info_; }
  const std::optional<EurocCameraInfo>& cam1Info() const { return cam1_info_; }
  const std::optional<EurocImuInfo>& imuInfo() const { return imu_info_; }
  const std::string& mav0() const { return mav0_; }

 private:
  struct Frame {
    int64_t t_ns;
    std::string left, right;  // image paths
  };
  std::string mav0_;
  std::vector<Frame> frames_;
  int unpaired_left_ = 0, unpaired_right_ = 0;
  cv::Size image_size_;
  std::vector<ImuSample> imu_;
  std::vector<int64_t> imu_t_ns_;
  std::vector<EurocGroundTruth> ground_truth_;
  std::optional<EurocCameraInfo> cam0_info_, cam1_info_;
  std::optional<EurocImuInfo> imu_info_;
};

}  // namespace cvslam
