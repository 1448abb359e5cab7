#include "cvslam/scenario/gps_options.h"

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

const std::vector<std::pair<std::string, GpsNoiseKind>>& gpsNoiseKindNames() {
  static const std::vector<std::pair<std::string, GpsNoiseKind>> names = {
      {"gaussian", GpsNoiseKind::kGaussian},
      {"student_t", GpsNoiseKind::kStudentT},
      {"mixture", GpsNoiseKind::kMixture}};
  return names;
}

Status GpsOptions::load(const ConfigNode& node) {
  node.get("rate_hz", rate_hz);
  node.get("start_s", start_s);
  node.get("sigma_horizontal", sigma_horizontal);
  node.get("sigma_vertical", sigma_vertical);
  node.get("sigma_velocity", sigma_velocity);
  node.getEnum("kind", kind, gpsNoiseKindNames());
  node.get("student_dof", student_dof);
  node.get("bias_random_walk", bias_random_walk);
  node.get("bias_initial", bias_initial);
  if (node.has("outages")) {
    outages.clear();
    for (const ConfigNode& w : node.sequence("outages")) {
      GpsOutage o;
      w.require("start_s", o.start_s);
      w.require("end_s", o.end_s);
      w.check(o.end_s > o.start_s, "end_s", "must be > start_s");
      outages.push_back(o);
    }
  }
  node.check(rate_hz > 0.0 && rate_hz <= 100.0, "rate_hz", "must be in (0, 100]");
  node.check(start_s >= 0.0, "start_s", "must be >= 0");
  node.check(sigma_horizontal >= 0.0, "sigma_horizontal", "must be >= 0");
  node.check(sigma_vertical >= 0.0, "sigma_vertical", "must be >= 0");
  node.check(sigma_velocity >= 0.0, "sigma_velocity", "must be >= 0");
  node.check(student_dof > 2, "student_dof", "must be > 2 (finite variance)");
  node.check(bias_random_walk >= 0.0, "bias_random_walk", "must be >= 0");
  return node.status();
}

bool GpsOptions::inOutage(double t_s) const {
  for (const GpsOutage& o : outages)
    if (t_s >= o.start_s && t_s < o.end_s) return true;
  return false;
}

}  // namespace cvslam::sim
