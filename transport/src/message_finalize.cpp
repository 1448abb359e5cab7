#include "cvslam/lcm/message_finalize.h"

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace cvslam::transport {
namespace {

// Sets `count` from the first array of a family and checks the other arrays against it.
class CountSetter {
 public:
  template <typename T>
  CountSetter& leading(const char* field, const std::vector<T>& v, int32_t& count) {
    if (v.size() > static_cast<std::size_t>(std::numeric_limits<int32_t>::max())) {
      fail(std::string(field) + " has too many elements");
      return *this;
    }
    count = static_cast<int32_t>(v.size());
    n_ = v.size();
    return *this;
  }
  template <typename T>
  CountSetter& same(const char* field, const std::vector<T>& v) {
    if (v.size() != n_) {
      fail(std::string(field) + " has " + std::to_string(v.size()) + " elements, expected " +
           std::to_string(n_));
    }
    return *this;
  }
  /// Rows of a fixed width (e.g. position[n][3]).
  template <typename T>
  CountSetter& rows(const char* field, const std::vector<std::vector<T>>& v, std::size_t width) {
    same(field, v);
    for (const auto& row : v) {
      if (row.size() != width) {
        fail(std::string(field) + " row has " + std::to_string(row.size()) +
             " elements, expected " + std::to_string(width));
        break;
      }
    }
    return *this;
  }
  /// Rows of a variable but common width (descriptors[n][length]); sets `length`.
  CountSetter& commonRows(const char* field, const std::vector<std::vector<uint8_t>>& v,
                          int32_t& length) {
    same(field, v);
    if (v.empty()) return *this;  // length is irrelevant without rows; keep the caller's
    length = static_cast<int32_t>(v.front().size());
    for (const auto& row : v) {
      if (row.size() != v.front().size()) {
        fail(std::string(field) + " rows differ in length");
        break;
      }
    }
    return *this;
  }
  Status status() const { return error_.empty() ? Status::Ok() : Status::Error(error_); }

 private:
  void fail(std::string message) {
    if (error_.empty()) error_ = std::move(message);
  }
  std::size_t n_ = 0;
  std::string error_;
};

}  // namespace

Status finalize(cvslam::imu_t&) {
  return Status::Ok();
}
Status finalize(cvslam::pose_t&) {
  return Status::Ok();
}

Status finalize(cvslam::stereo_image_t& msg) {
  CountSetter c;
  c.leading("left_data", msg.left_data, msg.left_size);
  c.leading("right_data", msg.right_data, msg.right_size);
  return c.status();
}

Status finalize(cvslam::stereo_features_t& msg) {
  return CountSetter()
      .leading("index", msg.index, msg.num_features)
      .same("u_left", msg.u_left)
      .same("v_left", msg.v_left)
      .same("u_right", msg.u_right)
      .same("v_right", msg.v_right)
      .commonRows("descriptors", msg.descriptors, msg.descriptor_length)
      .status();
}

Status finalize(cvslam::agent_map_t& msg) {
  return CountSetter()
      .leading("id", msg.id, msg.num_landmarks)
      .rows("position", msg.position, 3)
      .same("position_std", msg.position_std)
      .same("active", msg.active)
      .status();
}

Status finalize(cvslam::agent_state_t& msg) {
  CountSetter c;
  c.leading("state", msg.state, msg.state_dim);
  c.leading("covariance", msg.covariance, msg.covariance_size);
  return c.status();
}

Status finalize(cvslam::agent_summary_t& msg) {
  return CountSetter()
      .leading("channel", msg.channel, msg.num_channels)
      .same("received", msg.received)
      .same("dropped", msg.dropped)
      .same("invalid", msg.invalid)
      .status();
}

Status finalize(cvslam::feature_index_t& msg) {
  return CountSetter().leading("index", msg.index, msg.num_indices).status();
}

Status finalize(cvslam::shared_request_t& msg) {
  return CountSetter().leading("index", msg.index, msg.num_indices).status();
}

Status finalize(cvslam::shared_landmarks2_t& msg) {
  return CountSetter()
      .leading("informed_by", msg.informed_by, msg.num_informed_by)
      .leading("index", msg.index, msg.num_landmarks)
      .rows("position", msg.position, 3)
      .rows("covariance", msg.covariance, 6)
      .commonRows("descriptors", msg.descriptors, msg.descriptor_length)
      .leading("cross_covariance", msg.cross_covariance, msg.num_cross)
      .rows("cross_covariance", msg.cross_covariance, 9)
      .status();
}

Status finalize(cvslam::observation_batch_t& msg) {
  CountSetter c;
  c.leading("imu_age_us", msg.imu_age_us, msg.num_imu)
      .rows("gyro", msg.gyro, 3)
      .rows("accel", msg.accel, 3);
  c.leading("index", msg.index, msg.num_features)
      .same("type", msg.type)
      .same("landmark_id", msg.landmark_id)
      .same("u_left", msg.u_left)
      .same("v_left", msg.v_left)
      .same("u_right", msg.u_right)
      .same("v_right", msg.v_right)
      .commonRows("descriptors", msg.descriptors, msg.descriptor_length);
  return c.status();
}

Status finalize(cvslam::gs_state_t& msg) {
  CountSetter c;
  c.leading("state", msg.state, msg.state_dim);
  c.leading("covariance", msg.covariance, msg.covariance_size);
  return c.status();
}

Status finalize(cvslam::map_t& msg) {
  return CountSetter()
      .leading("index", msg.index, msg.num_landmarks)
      .rows("position", msg.position, 3)
      .rows("covariance", msg.covariance, 6)
      .status();
}

Status finalize(cvslam::status_t&) {
  return Status::Ok();
}

}  // namespace cvslam::transport
