#include "cvslam/lcm/message_validate.h"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace cvslam::transport {
namespace {

// Collects the first violation; every check is a no-op once one has failed.
class Checker {
 public:
  explicit Checker(const cvslam::header_t& header) {
    require(header.seq >= 0, "header.seq is negative");
  }

  Checker& require(bool condition, const char* what) {
    if (!condition) fail(what);
    return *this;
  }
  template <typename T>
  Checker& count(const char* field, int32_t count, const std::vector<T>& v) {
    if (count < 0 || static_cast<std::size_t>(count) != v.size()) {
      fail(std::string("count of ") + field + " is " + std::to_string(count) + " but it has " +
           std::to_string(v.size()) + " elements");
    }
    return *this;
  }
  template <typename T>
  Checker& rows(const char* field, int32_t count, const std::vector<std::vector<T>>& v,
                int32_t width) {
    this->count(field, count, v);
    for (const auto& row : v) {
      if (width < 0 || row.size() != static_cast<std::size_t>(width)) {
        fail(std::string(field) + " has a row of the wrong length");
        break;
      }
    }
    return *this;
  }
  Checker& finite(const char* field, double value) {
    if (!std::isfinite(value)) fail(std::string(field) + " is not finite");
    return *this;
  }
  template <std::size_t N>
  Checker& finite(const char* field, const double (&values)[N]) {
    for (double x : values) finite(field, x);
    return *this;
  }
  template <typename T>
  Checker& finite(const char* field, const std::vector<T>& values) {
    for (T x : values) finite(field, static_cast<double>(x));
    return *this;
  }
  template <typename T>
  Checker& finite(const char* field, const std::vector<std::vector<T>>& rows) {
    for (const auto& row : rows) finite(field, row);
    return *this;
  }
  // An LCM string ends at its first NUL byte: one inside it is encoded as a shorter string
  // than the message holds (the publisher refuses it), so a receiver refuses it too.
  Checker& text(const char* field, const std::string& value) {
    if (value.find('\0') != std::string::npos) fail(std::string(field) + " holds a NUL byte");
    return *this;
  }
  Checker& text(const char* field, const std::vector<std::string>& values) {
    for (const std::string& v : values) text(field, v);
    return *this;
  }
  Status status() const { return error_.empty() ? Status::Ok() : Status::Error(error_); }

 private:
  void fail(std::string message) {
    if (error_.empty()) error_ = std::move(message);
  }
  std::string error_;
};

bool isVehicleDim(int32_t dim) {
  return dim == 9 || dim == 15;
}

template <typename Msg>
Status validateVehicleEstimate(Checker& c, const Msg& msg) {
  c.require(isVehicleDim(msg.state_dim), "state_dim must be 9 or 15")
      .count("state", msg.state_dim, msg.state)
      .count("covariance", msg.covariance_size, msg.covariance)
      .require(msg.covariance_size == msg.state_dim * msg.state_dim,
               "covariance_size must be state_dim²")
      .finite("state", msg.state)
      .finite("covariance", msg.covariance);
  return c.status();
}

bool hasPngSignature(const std::vector<uint8_t>& data) {
  static constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (data.size() < sizeof(kSignature)) return false;
  for (std::size_t i = 0; i < sizeof(kSignature); ++i) {
    if (data[i] != kSignature[i]) return false;
  }
  return true;
}

}  // namespace

Status validate(const cvslam::imu_t& msg) {
  return Checker(msg.header).finite("gyro", msg.gyro).finite("accel", msg.accel).status();
}

Status validate(const cvslam::stereo_image_t& msg) {
  Checker c(msg.header);
  c.count("left_data", msg.left_size, msg.left_data)
      .count("right_data", msg.right_size, msg.right_data)
      .require(msg.width > 0 && msg.height > 0, "image width and height must be positive");
  if (msg.encoding == cvslam::stereo_image_t::ENCODING_MONO8) {
    const int64_t expected = static_cast<int64_t>(msg.stride) * msg.height;
    c.require(msg.stride >= msg.width, "mono8 stride must be at least the width")
        .require(msg.left_size == expected && msg.right_size == expected,
                 "mono8 image size must be stride·height");
  } else if (msg.encoding == cvslam::stereo_image_t::ENCODING_PNG) {
    c.require(msg.stride == 0, "PNG images have stride 0")
        .require(hasPngSignature(msg.left_data) && hasPngSignature(msg.right_data),
                 "PNG data lacks the PNG signature");
  } else {
    c.require(false, "unknown image encoding");
  }
  return c.status();
}

Status validate(const cvslam::stereo_features_t& msg) {
  return Checker(msg.header)
      .count("index", msg.num_features, msg.index)
      .count("u_left", msg.num_features, msg.u_left)
      .count("v_left", msg.num_features, msg.v_left)
      .count("u_right", msg.num_features, msg.u_right)
      .count("v_right", msg.num_features, msg.v_right)
      .rows("descriptors", msg.num_features, msg.descriptors, msg.descriptor_length)
      .require(msg.descriptor_length >= 0, "descriptor_length is negative")
      .finite("u_left", msg.u_left)
      .finite("v_left", msg.v_left)
      .finite("u_right", msg.u_right)
      .finite("v_right", msg.v_right)
      .status();
}

Status validate(const cvslam::pose_t& msg) {
  return Checker(msg.header)
      .finite("position", msg.position)
      .finite("quaternion", msg.quaternion)
      .finite("euler", msg.euler)
      .finite("velocity", msg.velocity)
      .status();
}

Status validate(const cvslam::agent_map_t& msg) {
  Checker c(msg.header);
  c.count("id", msg.num_landmarks, msg.id)
      .rows("position", msg.num_landmarks, msg.position, 3)
      .count("position_std", msg.num_landmarks, msg.position_std)
      .count("active", msg.num_landmarks, msg.active)
      .finite("position", msg.position)
      .finite("position_std", msg.position_std);
  for (int64_t id : msg.id) c.require(id >= 0, "negative landmark id");
  for (float s : msg.position_std) c.require(s >= 0.0f, "negative position_std");
  return c.status();
}

Status validate(const cvslam::agent_state_t& msg) {
  Checker c(msg.header);
  c.require(msg.num_landmarks >= 0 && msg.num_archived >= 0, "negative landmark count")
      .text("filter", msg.filter);
  return validateVehicleEstimate(c, msg);
}

Status validate(const cvslam::agent_summary_t& msg) {
  Checker c(msg.header);
  c.finite("ellipsoid_mean", msg.ellipsoid_mean)
      .finite("ellipsoid_std", msg.ellipsoid_std)
      .finite("vehicle_cov_trace", msg.vehicle_cov_trace)
      .require(msg.num_features >= 0, "num_features is negative")
      .count("channel", msg.num_channels, msg.channel)
      .count("received", msg.num_channels, msg.received)
      .count("dropped", msg.num_channels, msg.dropped)
      .count("invalid", msg.num_channels, msg.invalid)
      .text("mode", msg.mode)
      .text("channel", msg.channel);
  for (double s : msg.ellipsoid_std) c.require(s >= 0.0, "ellipsoid_std is negative");
  return c.status();
}

Status validate(const cvslam::feature_index_t& msg) {
  return Checker(msg.header).count("index", msg.num_indices, msg.index).status();
}

Status validate(const cvslam::shared_request_t& msg) {
  return Checker(msg.header).count("index", msg.num_indices, msg.index).status();
}

Status validate(const cvslam::shared_landmarks2_t& msg) {
  return Checker(msg.header)
      .finite("vehicle_cov_trace", msg.vehicle_cov_trace)
      .count("informed_by", msg.num_informed_by, msg.informed_by)
      .count("index", msg.num_landmarks, msg.index)
      .rows("position", msg.num_landmarks, msg.position, 3)
      .rows("covariance", msg.num_landmarks, msg.covariance, 6)
      .rows("cross_covariance", msg.num_cross, msg.cross_covariance, 9)
      .require(msg.num_cross == 0 || int64_t{msg.num_cross} * 2 ==
                                         int64_t{msg.num_landmarks} * (msg.num_landmarks - 1),
               "num_cross is neither 0 nor num_landmarks·(num_landmarks−1)/2")
      .finite("cross_covariance", msg.cross_covariance)
      .rows("descriptors", msg.num_landmarks, msg.descriptors, msg.descriptor_length)
      .require(msg.descriptor_length >= 0, "descriptor_length is negative")
      .finite("position", msg.position)
      .finite("covariance", msg.covariance)
      .status();
}

Status validate(const cvslam::observation_batch_t& msg) {
  Checker c(msg.header);
  c.count("imu_age_us", msg.num_imu, msg.imu_age_us)
      .rows("gyro", msg.num_imu, msg.gyro, 3)
      .rows("accel", msg.num_imu, msg.accel, 3)
      .finite("gyro", msg.gyro)
      .finite("accel", msg.accel)
      .count("index", msg.num_features, msg.index)
      .count("type", msg.num_features, msg.type)
      .count("landmark_id", msg.num_features, msg.landmark_id)
      .count("u_left", msg.num_features, msg.u_left)
      .count("v_left", msg.num_features, msg.v_left)
      .count("u_right", msg.num_features, msg.u_right)
      .count("v_right", msg.num_features, msg.v_right)
      .rows("descriptors", msg.num_features, msg.descriptors, msg.descriptor_length)
      .require(msg.descriptor_length >= 0, "descriptor_length is negative")
      .finite("u_left", msg.u_left)
      .finite("v_left", msg.v_left)
      .finite("u_right", msg.u_right)
      .finite("v_right", msg.v_right);
  for (int8_t type : msg.type) {
    c.require(type >= cvslam::observation_batch_t::TYPE_REOBSERVED &&
                  type <= cvslam::observation_batch_t::TYPE_NEW,
              "unknown observation type");
  }
  for (int64_t id : msg.landmark_id) c.require(id >= -1, "landmark_id below -1");
  for (int32_t age : msg.imu_age_us) c.require(age >= 0, "IMU sample after the frame");
  return c.status();
}

Status validate(const cvslam::gs_state_t& msg) {
  Checker c(msg.header);
  c.text("filter", msg.filter);
  return validateVehicleEstimate(c, msg);
}

Status validate(const cvslam::map_t& msg) {
  return Checker(msg.header)
      .count("index", msg.num_landmarks, msg.index)
      .rows("position", msg.num_landmarks, msg.position, 3)
      .rows("covariance", msg.num_landmarks, msg.covariance, 6)
      .finite("position", msg.position)
      .finite("covariance", msg.covariance)
      .status();
}

Status validate(const cvslam::status_t& msg) {
  return Checker(msg.header)
      .require(msg.health >= cvslam::status_t::HEALTH_OK &&
                   msg.health <= cvslam::status_t::HEALTH_FAILED,
               "unknown health value")
      .text("message", msg.message)
      .status();
}

}  // namespace cvslam::transport
