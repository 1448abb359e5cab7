#include "cvslam/io/tum_trajectory.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "cvslam/geometry/euler.h"

namespace cvslam {

TumPose tumPoseFromState(double t, const Eigen::Matrix<double, 9, 1>& x_v) {
  TumPose p;
  p.t = t;
  p.p_BinN = x_v.head<3>();
  p.q_BtoN = Eigen::Quaterniond(rotationBodyToNav(Eigen::Vector3d(x_v.tail<3>())));
  return p;
}

Expected<std::vector<TumPose>> readTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open trajectory");
  std::vector<TumPose> poses;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string at = path + ":" + std::to_string(line_no) + ": ";
    std::istringstream fields(line);
    std::vector<double> v;
    std::string token;
    while (fields >> token) {
      char* end = nullptr;
      const double x = std::strtod(token.c_str(), &end);
      if (*end != '\0' || !std::isfinite(x))
        return Status::Error(at + "not a finite number: '" + token + "'");
      v.push_back(x);
    }
    if (v.size() != 8)
      return Status::Error(at + "expected 8 fields 't x y z qx qy qz qw', got " +
                           std::to_string(v.size()));
    TumPose p;
    p.t = v[0];
    p.p_BinN = {v[1], v[2], v[3]};
    p.q_BtoN = Eigen::Quaterniond(v[7], v[4], v[5], v[6]);
    if (p.q_BtoN.norm() < 1e-6) return Status::Error(at + "zero quaternion");
    p.q_BtoN.normalize();
    if (!poses.empty() && !(p.t > poses.back().t)) {
      std::ostringstream os;
      os.precision(12);
      os << at << "time " << p.t << " s is not after the previous " << poses.back().t
         << " s (times must increase)";
      return Status::Error(os.str());
    }
    poses.push_back(p);
  }
  return poses;
}

Status TumWriter::open(const std::string& path, const std::string& comment) {
  path_ = path;
  out_.open(path, std::ios::trunc);
  if (!out_) return Status::Error(path + ": cannot write trajectory");
  if (!comment.empty()) out_ << "# " << comment << '\n';
  out_ << "# t x y z qx qy qz qw\n";
  return Status::Ok();
}

Status TumWriter::add(const TumPose& pose) {
  if (!out_.is_open()) return Status::Error("TumWriter: not open");
  if (!(pose.t > last_t_)) return Status::Error(path_ + ": times must increase");
  last_t_ = pose.t;
  const Eigen::Quaterniond& q = pose.q_BtoN;
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%.9f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", pose.t,
                pose.p_BinN.x(), pose.p_BinN.y(), pose.p_BinN.z(), q.x(), q.y(), q.z(), q.w());
  out_ << buf;
  if (!out_) return Status::Error(path_ + ": write failed");
  return Status::Ok();
}

Status writeTumTrajectory(const std::string& path, const std::vector<TumPose>& poses) {
  TumWriter w;
  if (Status s = w.open(path); !s.ok()) return s;
  for (const TumPose& p : poses)
    if (Status s = w.add(p); !s.ok()) return s;
  return Status::Ok();
}

}  // namespace cvslam
