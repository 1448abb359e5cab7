#pragma once
// TUM trajectory files (docs/run_format.md): one pose per line, `t x y z qx qy qz qw`, t in
// seconds, position p_BinN [m], quaternion q_BtoN (rotates body vectors into N, i.e. the
// body's orientation in N, as TUM tools expect). Lines starting with '#' are comments.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <fstream>
#include <string>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

struct TumPose {
  double t = 0.0;                                              ///< [s]
  Eigen::Vector3d p_BinN = Eigen::Vector3d::Zero();            ///< [m]
  Eigen::Quaterniond q_BtoN = Eigen::Quaterniond::Identity();  ///< unit quaternion
};

/// TUM pose of a vehicle state [p_BinN, v_B, euler] (velocity unused).
TumPose tumPoseFromState(double t, const Eigen::Matrix<double, 9, 1>& x_v);

/// Reads a TUM file. Errors name "file:line" for a wrong field count, a non-number, a
/// zero quaternion, or a time not strictly after the previous one.
Expected<std::vector<TumPose>> readTumTrajectory(const std::string& path);

/// Writes a whole trajectory (overwrites).
Status writeTumTrajectory(const std::string& path, const std::vector<TumPose>& poses);

/// Appends poses to a TUM file as they are produced (an estimator run). Times must increase.
class TumWriter {
 public:
  /// Creates or truncates `path`; a non-empty `comment` becomes a first line "# comment"
  /// (TUM readers skip it).
  Status open(const std::string& path, const std::string& comment = "");
  Status add(const TumPose& pose);
  bool isOpen() const { return out_.is_open(); }
  void close() { out_.close(); }
  void flush() { out_.flush(); }

 private:
  std::ofstream out_;
  std::string path_;
  double last_t_ = -1e300;
};

}  // namespace cvslam
