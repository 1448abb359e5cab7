#include "cvslam/dataset/euroc_dataset_writer.h"
#include "cvslam/io/number_format.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <tuple>

namespace cvslam {
namespace fs = std::filesystem;
namespace {

Status writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) return Status::Error(path + ": cannot write");
  return Status::Ok();
}

Status openCsv(const std::string& path, const std::string& header, std::ofstream& out) {
  out.open(path);
  if (!out) return Status::Error(path + ": cannot create");
  out << header << '\n';
  return Status::Ok();
}

}  // namespace

EurocCameraInfo eurocCameraInfo(const StereoCameraOptions& c, bool right, double rate_hz) {
  EurocCameraInfo info;
  info.comment = right ? "cvslam rectified right camera" : "cvslam rectified left camera";
  const Eigen::Matrix3d R_CtoB = c.R_BtoC.transpose();
  info.T_BS.topLeftCorner<3, 3>() = R_CtoB;
  info.T_BS.topRightCorner<3, 1>() =
      c.p_CinB + (right ? Eigen::Vector3d(R_CtoB * Eigen::Vector3d(c.baseline, 0, 0))
                        : Eigen::Vector3d::Zero());
  info.rate_hz = rate_hz;
  info.width = c.width;
  info.height = c.height;
  info.intrinsics = {c.fx, c.fy, c.cx, c.cy};
  info.distortion = {0.0, 0.0, 0.0, 0.0};  // rectified images
  return info;
}

Expected<EurocDatasetWriter> EurocDatasetWriter::create(const std::string& path,
                                                        const EurocWriterOptions& options) {
  EurocDatasetWriter w;
  w.mav0_ = path + "/mav0";
  w.options_ = options;
  if (fs::exists(w.mav0_)) return Status::Error(w.mav0_ + ": already exists");
  std::error_code ec;
  for (const char* sub : {"cam0/data", "cam1/data", "imu0", "state_groundtruth_estimate0"}) {
    fs::create_directories(w.mav0_ + "/" + sub, ec);
    if (ec) return Status::Error(w.mav0_ + "/" + sub + ": cannot create: " + ec.message());
  }
  const bool raw = options.cameras.size() == 2;
  if (!raw && !options.cameras.empty())
    return Status::Error(w.mav0_ + ": give both cameras' sensor.yaml or none");
  Status s = writeText(
      w.mav0_ + "/cam0/sensor.yaml",
      formatEurocCameraYaml(raw ? options.cameras[0]
                                : eurocCameraInfo(options.camera, false, options.camera_rate_hz)));
  if (s.ok())
    s = writeText(
        w.mav0_ + "/cam1/sensor.yaml",
        formatEurocCameraYaml(raw ? options.cameras[1]
                                  : eurocCameraInfo(options.camera, true, options.camera_rate_hz)));
  if (s.ok()) s = writeText(w.mav0_ + "/imu0/sensor.yaml", formatEurocImuYaml(options.imu));
  if (s.ok())
    s = writeText(w.mav0_ + "/state_groundtruth_estimate0/sensor.yaml",
                  "%YAML:1.0\nsensor_type: visual-inertial\ncomment: cvslam ground truth (body "
                  "= IMU) in the navigation frame\n");
  if (s.ok())
    s = writeText(w.mav0_ + "/body.yaml",
                  "%YAML:1.0\ncomment: cvslam body frame (FRD) = IMU frame\n");
  if (s.ok()) s = openCsv(w.mav0_ + "/cam0/data.csv", "#timestamp [ns],filename", w.cam0_csv_);
  if (s.ok()) s = openCsv(w.mav0_ + "/cam1/data.csv", "#timestamp [ns],filename", w.cam1_csv_);
  if (s.ok())
    s = openCsv(w.mav0_ + "/imu0/data.csv",
                "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]",
                w.imu_csv_);
  if (s.ok())
    s = openCsv(w.mav0_ + "/state_groundtruth_estimate0/data.csv",
                "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
                "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
                "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
                "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]",
                w.gt_csv_);
  if (!s.ok()) return s;
  return w;
}

Status EurocDatasetWriter::addStereoFrame(int64_t t_ns, const cv::Mat& left, const cv::Mat& right) {
  if (t_ns <= last_frame_ns_)
    return Status::Error(mav0_ + ": frame timestamp " + std::to_string(t_ns) +
                         " does not increase");
  const cv::Size size = options_.cameras.size() == 2
                            ? cv::Size(options_.cameras[0].width, options_.cameras[0].height)
                            : cv::Size(options_.camera.width, options_.camera.height);
  for (const cv::Mat* m : {&left, &right})
    if (m->type() != CV_8UC1 || m->size() != size)
      return Status::Error(mav0_ + ": frame " + std::to_string(t_ns) + ": images must be " +
                           std::to_string(size.width) + "x" + std::to_string(size.height) +
                           " mono8");
  const std::string name = std::to_string(t_ns) + ".png";
  for (auto [cam, image, csv] :
       {std::tuple{"cam0", &left, &cam0_csv_}, std::tuple{"cam1", &right, &cam1_csv_}}) {
    const std::string path = mav0_ + "/" + cam + "/data/" + name;
    if (!cv::imwrite(path, *image)) return Status::Error(path + ": cannot write PNG");
    *csv << t_ns << ',' << name << '\n';
  }
  last_frame_ns_ = t_ns;
  return Status::Ok();
}

Status EurocDatasetWriter::addImu(const ImuSample& m) {
  const int64_t t_ns = m.t_us * 1000;
  if (t_ns <= last_imu_ns_)
    return Status::Error(mav0_ + ": IMU timestamp " + std::to_string(t_ns) + " does not increase");
  imu_csv_ << t_ns << ',' << formatShortest(m.gyro_B.x()) << ',' << formatShortest(m.gyro_B.y())
           << ',' << formatShortest(m.gyro_B.z()) << ',' << formatShortest(m.accel_B.x()) << ','
           << formatShortest(m.accel_B.y()) << ',' << formatShortest(m.accel_B.z()) << '\n';
  last_imu_ns_ = t_ns;
  return Status::Ok();
}

Status EurocDatasetWriter::addGroundTruth(const EurocGroundTruth& g) {
  if (g.t_ns <= last_gt_ns_)
    return Status::Error(mav0_ + ": ground-truth timestamp " + std::to_string(g.t_ns) +
                         " does not increase");
  gt_csv_ << g.t_ns;
  const Eigen::Quaterniond& q = g.q_StoR;
  for (double x : {g.p_SinR.x(), g.p_SinR.y(), g.p_SinR.z(), q.w(), q.x(), q.y(), q.z(),
                   g.v_SinR.x(), g.v_SinR.y(), g.v_SinR.z(), g.gyro_bias.x(), g.gyro_bias.y(),
                   g.gyro_bias.z(), g.accel_bias.x(), g.accel_bias.y(), g.accel_bias.z()})
    gt_csv_ << ',' << formatShortest(x);
  gt_csv_ << '\n';
  last_gt_ns_ = g.t_ns;
  return Status::Ok();
}

Status EurocDatasetWriter::close() {
  for (std::ofstream* f : {&cam0_csv_, &cam1_csv_, &imu_csv_, &gt_csv_}) {
    if (!f->is_open()) continue;
    f->close();
    if (!*f) return Status::Error(mav0_ + ": error while writing a data.csv");
  }
  return Status::Ok();
}

}  // namespace cvslam
