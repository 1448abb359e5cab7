#include "cvslam/ins/initial_uncertainty.h"

#include "cvslam/io/config_node.h"

namespace cvslam {

Status InitialUncertainty::load(const ConfigNode& node) {
  Eigen::Vector3d attitude_deg = attitude_sigma * (180.0 / M_PI);
  node.get("position_sigma", position_sigma);
  node.get("velocity_sigma", velocity_sigma);
  node.get("attitude_sigma_deg", attitude_deg);
  node.get("perturb", perturb);
  node.get("perturb_biases", perturb_biases);
  node.check(position_sigma.minCoeff() >= 0.0, "position_sigma", "must be >= 0");
  node.check(velocity_sigma.minCoeff() >= 0.0, "velocity_sigma", "must be >= 0");
  node.check(attitude_deg.minCoeff() >= 0.0, "attitude_sigma_deg", "must be >= 0");
  attitude_sigma = attitude_deg * (M_PI / 180.0);
  return node.status();
}

}  // namespace cvslam
