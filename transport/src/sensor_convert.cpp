#include "cvslam/lcm/sensor_convert.h"

#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "cvslam/geometry/euler.h"
#include "cvslam/lcm/features_convert.h"
#include "cvslam/lcm/imu_convert.h"

namespace cvslam::transport {
namespace {

Status copyImage(const cv::Mat& image, bool png, std::vector<uint8_t>& out) {
  if (png) {
    if (!cv::imencode(".png", image, out, {cv::IMWRITE_PNG_COMPRESSION, 1}))
      return Status::Error("PNG encoding failed");
    return Status::Ok();
  }
  out.resize(image.total());
  for (int r = 0; r < image.rows; ++r) {
    const uint8_t* row = image.ptr<uint8_t>(r);
    std::copy(row, row + image.cols, out.begin() + static_cast<std::ptrdiff_t>(r) * image.cols);
  }
  return Status::Ok();
}

Status decodeImage(const cvslam::stereo_image_t& msg, const std::vector<uint8_t>& data,
                   cv::Mat& image) {
  if (msg.encoding == cvslam::stereo_image_t::ENCODING_PNG) {
    image = cv::imdecode(data, cv::IMREAD_UNCHANGED);
    if (image.empty() || image.type() != CV_8UC1 || image.cols != msg.width ||
        image.rows != msg.height)
      return Status::Error(
          "stereo_image_t: PNG does not decode to a mono8 image of the stated size");
    return Status::Ok();
  }
  image.create(msg.height, msg.width, CV_8UC1);
  for (int r = 0; r < msg.height; ++r) {
    std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(r) * msg.stride, msg.width,
                image.ptr<uint8_t>(r));
  }
  return Status::Ok();
}

}  // namespace

cvslam::pose_t toPoseMessage(const VehiclePose& pose, int64_t t_us, int32_t sender_id) {
  cvslam::pose_t msg{};
  msg.header.utime = t_us;
  msg.header.agent_id = sender_id;
  const Eigen::Quaterniond q = pose.q_BtoN.normalized();
  msg.quaternion[0] = q.w();
  msg.quaternion[1] = q.x();
  msg.quaternion[2] = q.y();
  msg.quaternion[3] = q.z();
  for (int i = 0; i < 3; ++i) {
    msg.position[i] = pose.p_BinN[i];
    msg.euler[i] = pose.euler[i];
    msg.velocity[i] = pose.v_N[i];
  }
  return msg;
}

VehiclePose fromPoseMessage(const cvslam::pose_t& msg) {
  VehiclePose pose;
  pose.q_BtoN =
      Eigen::Quaterniond(msg.quaternion[0], msg.quaternion[1], msg.quaternion[2], msg.quaternion[3])
          .normalized();
  for (int i = 0; i < 3; ++i) {
    pose.p_BinN[i] = msg.position[i];
    pose.euler[i] = msg.euler[i];
    pose.v_N[i] = msg.velocity[i];
  }
  return pose;
}

Expected<cvslam::stereo_image_t> toStereoMessage(const cv::Mat& left, const cv::Mat& right,
                                                 int64_t t_us, int32_t sender_id, bool png) {
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size() ||
      left.empty())
    return Status::Error("stereo pair must be two mono8 images of the same size");
  cvslam::stereo_image_t msg{};
  msg.header.utime = t_us;
  msg.header.agent_id = sender_id;
  msg.encoding =
      png ? cvslam::stereo_image_t::ENCODING_PNG : cvslam::stereo_image_t::ENCODING_MONO8;
  msg.width = left.cols;
  msg.height = left.rows;
  msg.stride = png ? 0 : left.cols;
  Status s = copyImage(left, png, msg.left_data);
  if (s.ok()) s = copyImage(right, png, msg.right_data);
  if (!s.ok()) return s;
  msg.left_size = static_cast<int32_t>(msg.left_data.size());
  msg.right_size = static_cast<int32_t>(msg.right_data.size());
  return msg;
}

Status fromStereoMessage(const cvslam::stereo_image_t& msg, cv::Mat& left, cv::Mat& right) {
  Status s = decodeImage(msg, msg.left_data, left);
  if (s.ok()) s = decodeImage(msg, msg.right_data, right);
  return s;
}

Vector9d truthState(const VehiclePose& pose) {
  Vector9d x;
  const Eigen::Vector3d v_B = rotationBodyToNav<double>(pose.euler).transpose() * pose.v_N;
  x << pose.p_BinN, v_B, pose.euler;
  return x;
}

namespace {
template <typename Msg>
void stamp(const Msg& msg, SensorEventType type, int agent_id, SensorEvent* e) {
  *e = SensorEvent{};
  e->type = type;
  e->agent_id = agent_id;
  e->t_us = msg.header.utime;
}
}  // namespace

bool toSensorEvent(const cvslam::imu_t& msg, int agent_id, SensorEvent* e) {
  stamp(msg, SensorEventType::kImu, agent_id, e);
  e->imu = fromMessage(msg);
  return true;
}

bool toSensorEvent(const cvslam::pose_t& msg, int agent_id, SensorEvent* e) {
  stamp(msg, SensorEventType::kGroundTruth, agent_id, e);
  e->truth = fromPoseMessage(msg);
  return true;
}

bool toSensorEvent(const cvslam::stereo_features_t& msg, int agent_id, SensorEvent* e) {
  stamp(msg, SensorEventType::kFeatures, agent_id, e);
  e->features = fromMessage(msg);
  return true;
}

bool toSensorEvent(const cvslam::stereo_image_t& msg, int agent_id, SensorEvent* e) {
  stamp(msg, SensorEventType::kStereoImage, agent_id, e);
  return fromStereoMessage(msg, e->left, e->right).ok();
}

}  // namespace cvslam::transport
