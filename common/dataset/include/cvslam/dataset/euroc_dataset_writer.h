#pragma once
// Writer for EuRoC ASL folders, the counterpart of EurocDataset (docs/run_format.md,
// docs/architecture.md):
//   <path>/mav0/{cam0,cam1}/{data.csv, data/<t_ns>.png, sensor.yaml},
//   imu0/{data.csv, sensor.yaml}, state_groundtruth_estimate0/data.csv, body.yaml,
// laid out and formatted as EuRoC's own files, so that Basalt and OpenVINS read them.
// Our images are rectified: distortion coefficients are zeros; cam1 is cam0 moved by the
// baseline along its x axis. T_BS = T_CtoB (sensor to body): R = R_BtoCᵀ, t = p_CinB.
// Numbers are written with 17 significant digits, so a read-back is exact.

#include <opencv2/core.hpp>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/dataset/euroc_sensor_yaml.h"
#include "cvslam/ins/imu_sample.h"

namespace cvslam {

struct EurocWriterOptions {
  StereoCameraOptions camera;    ///< intrinsics, baseline and mounting of the rectified pair
  double camera_rate_hz = 20.0;  ///< written to cam*/sensor.yaml
  EurocImuInfo imu;              ///< rate and noise model written to imu0/sensor.yaml
  /// When it holds two entries: cam0's and cam1's sensor.yaml as given (a raw, distorting
  /// rig, simrun/as_recorded_rig.h) instead of those of the rectified pair `camera`.
  std::vector<EurocCameraInfo> cameras;
};

/// The sensor.yaml content of the left (right = false) or right camera of a rectified pair.
EurocCameraInfo eurocCameraInfo(const StereoCameraOptions& camera, bool right, double rate_hz);

class EurocDatasetWriter {
 public:
  /// Creates the folder tree and the sensor.yaml files. Fails if <path>/mav0 already exists
  /// (never mixes two datasets).
  static Expected<EurocDatasetWriter> create(const std::string& path,
                                             const EurocWriterOptions& options);

  /// Both images (CV_8UC1, camera size) as data/<t_ns>.png; timestamps must increase.
  Status addStereoFrame(int64_t t_ns, const cv::Mat& left, const cv::Mat& right);
  /// One IMU row at t_ns = t_us · 1000.
  Status addImu(const ImuSample& sample);
  Status addGroundTruth(const EurocGroundTruth& state);
  /// Flushes and closes the CSV files; reports any write error.
  Status close();

  const std::string& mav0() const { return mav0_; }

 private:
  std::string mav0_;
  EurocWriterOptions options_;
  std::ofstream cam0_csv_, cam1_csv_, imu_csv_, gt_csv_;
  int64_t last_frame_ns_ = -1, last_imu_ns_ = -1, last_gt_ns_ = -1;
};

}  // namespace cvslam
