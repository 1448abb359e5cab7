#include "cvslam/scenario/imu_recording.h"

#include <algorithm>
#include <cmath>

#include "cvslam/io/csv_table.h"

namespace cvslam::sim {

Expected<std::shared_ptr<const ImuRecording>> ImuRecording::load(const std::string& path,
                                                                 const Eigen::Matrix3d& R_StoB) {
  auto table = readCsvTable(path);
  if (!table.ok()) return table.status();
  if (table->header.size() != 7)
    return Status::Error(path + ": expected 7 columns (t_ns, w_xyz, a_xyz), got " +
                         std::to_string(table->header.size()));
  if (table->rows.size() < 2) return Status::Error(path + ": fewer than 2 IMU samples");
  std::shared_ptr<ImuRecording> r(new ImuRecording());
  r->source_ = path;
  for (std::size_t i = 0; i < table->rows.size(); ++i) {
    const auto& row = table->rows[i];
    const double t = row[0] * 1e-9;
    if (!r->t_.empty() && t <= r->t_.back())
      return Status::Error(table->where(i) + ": timestamps must increase");
    r->t_.push_back(t);
    r->gyro_B_.push_back(R_StoB * Eigen::Vector3d(row[1], row[2], row[3]));
    r->accel_B_.push_back(R_StoB * Eigen::Vector3d(row[4], row[5], row[6]));
  }
  return std::shared_ptr<const ImuRecording>(r);
}

ImuSample ImuRecording::sampleAt(double t_s, int64_t t_us) const {
  ImuSample s;
  s.t_us = t_us;
  const double t = std::clamp(t_s, t_.front(), t_.back());
  std::size_t hi = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
  hi = std::clamp<std::size_t>(hi, 1, t_.size() - 1);
  const std::size_t lo = hi - 1;
  const double w = (t - t_[lo]) / (t_[hi] - t_[lo]);
  s.gyro_B = (1.0 - w) * gyro_B_[lo] + w * gyro_B_[hi];
  s.accel_B = (1.0 - w) * accel_B_[lo] + w * accel_B_[hi];
  return s;
}

std::vector<ImuSample> ImuRecording::samplesBefore(double zero_s) const {
  std::vector<ImuSample> out;
  for (std::size_t i = 0; i < t_.size() && t_[i] < zero_s; ++i) {
    ImuSample s;
    s.t_us = std::llround((t_[i] - zero_s) * 1e6);
    s.gyro_B = gyro_B_[i];
    s.accel_B = accel_B_[i];
    out.push_back(s);
  }
  return out;
}

}  // namespace cvslam::sim
