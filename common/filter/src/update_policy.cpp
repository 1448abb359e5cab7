#include "cvslam/filter/update_policy.h"

#include <sstream>

#include "cvslam/io/config_node.h"

namespace cvslam {

UpdatePolicy UpdatePolicy::ekf(double gate_probability) {
  UpdatePolicy p;
  p.gate_probability = gate_probability;
  return p;
}

double FilterOptions::measurementNoiseScale() const {
  if (type == FilterType::kEkf) return 1.0;
  return 1.0 - gamma * gamma * (delta1 * delta1 + delta3 * delta3);
}

Status FilterOptions::load(const ConfigNode& node) {
  node.getEnum("type", type, {{"ekf", FilterType::kEkf}, {"nhinf", FilterType::kNhinf}});
  node.get("gamma", gamma);
  node.get("delta1", delta1);
  node.get("delta2", delta2);
  node.get("delta3", delta3);
  node.get("theta_margin", theta_margin);
  node.get("gate_probability", gate_probability);
  node.getEnum("theta_weighting", theta_weighting,
               {{"observed", ThetaWeighting::kObserved}, {"identity", ThetaWeighting::kIdentity}});
  node.check(gamma > 0, "gamma", "must be > 0 (got " + std::to_string(gamma) + ")");
  node.check(delta1 >= 0 && delta2 >= 0 && delta3 >= 0, "delta1", "δ1, δ2, δ3 must be ≥ 0");
  node.check(theta_margin > 0 && theta_margin <= 1, "theta_margin", "must be in (0, 1]");
  node.check(gate_probability >= 0 && gate_probability < 1, "gate_probability",
             "must be in [0, 1)");
  if (type == FilterType::kNhinf) {
    const double cv2 = measurementNoiseScale();
    node.check(cv2 > 0, "gamma",
               "c_v² = 1 − γ²(δ1² + δ3²) must be > 0 (got " + std::to_string(cv2) +
                   "): lower gamma or the deltas");
  }
  return node.status();
}

std::string FilterOptions::print() const {
  std::ostringstream os;
  os.precision(17);
  os << "type: " << (type == FilterType::kEkf ? "ekf" : "nhinf") << "\n"
     << "gamma: " << gamma << "\n"
     << "delta1: " << delta1 << "\n"
     << "delta2: " << delta2 << "\n"
     << "delta3: " << delta3 << "\n"
     << "theta_margin: " << theta_margin << "\n"
     << "gate_probability: " << gate_probability << "\n";
  return os.str();
}

Expected<UpdatePolicy> FilterOptions::policy() const {
  UpdatePolicy p;
  p.gate_probability = gate_probability;
  p.theta_margin = theta_margin;
  p.theta_weighting = theta_weighting;
  if (type == FilterType::kEkf) return p;
  const double cv2 = measurementNoiseScale();
  if (!(cv2 > 0.0) || !(gamma > 0.0)) {
    return Status::Error("NH∞ parameters give c_v² = " + std::to_string(cv2) + " ≤ 0");
  }
  p.theta = 1.0 / (gamma * gamma);
  p.measurement_noise_scale = cv2;
  p.process_noise_scale = cv2 / (1.0 + delta2 * delta2);
  return p;
}

}  // namespace cvslam
