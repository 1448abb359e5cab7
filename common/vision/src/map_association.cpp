#include "cvslam/vision/map_association.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <limits>

#include "cvslam/io/config_node.h"

namespace cvslam::vision {

Status MapAssociationOptions::load(const ConfigNode& node) {
  node.getEnum("descriptor_type", descriptor_type,
               {{"sift", DescriptorType::kSift}, {"orb", DescriptorType::kOrb}});
  node.getEnum("norm", norm,
               {{"linf", MatchNorm::kLinf},
                {"l2", MatchNorm::kL2},
                {"angle", MatchNorm::kAngle},
                {"hamming", MatchNorm::kHamming}});
  node.get("gate_chi2", gate_chi2);
  node.get("max_descriptor_distance", max_descriptor_distance);
  node.get("dist_ratio", dist_ratio);
  node.check(gate_chi2 > 0, "gate_chi2", "must be > 0");
  node.check(max_descriptor_distance > 0, "max_descriptor_distance", "must be > 0");
  node.check(dist_ratio > 0 && dist_ratio <= 1, "dist_ratio", "must be in (0, 1]");
  return node.status();
}

Status associateToMap(const std::vector<LandmarkPrediction>& predictions,
                      const MapAssociationOptions& o, std::vector<StereoObservation>* observations,
                      AssociationStats* stats) {
  AssociationStats st;
  const int bytes = descriptorBytes(o.descriptor_type);
  const MatchNorm norm = o.descriptor_type == DescriptorType::kOrb
                             ? MatchNorm::kHamming
                             : (o.norm == MatchNorm::kHamming ? MatchNorm::kL2 : o.norm);
  for (StereoObservation& obs : *observations) {
    obs.type = ObservationType::kNew;
    obs.landmark_id = -1;
  }
  // Information matrices S⁻¹ (skip predictions whose S is not positive definite).
  std::vector<Eigen::Matrix4d> info(predictions.size());
  std::vector<bool> usable(predictions.size(), false);
  for (std::size_t p = 0; p < predictions.size(); ++p) {
    Eigen::LLT<Eigen::Matrix4d> llt(predictions[p].S);
    if (llt.info() != Eigen::Success) continue;
    if (static_cast<int>(predictions[p].descriptor.size()) != bytes) continue;
    info[p] = llt.solve(Eigen::Matrix4d::Identity());
    usable[p] = true;
  }
  struct Best {
    int landmark = -1;
    double d1 = std::numeric_limits<double>::infinity();
    double d2 = std::numeric_limits<double>::infinity();
  };
  std::vector<Best> best(observations->size());
  for (std::size_t i = 0; i < observations->size(); ++i) {
    const StereoObservation& obs = (*observations)[i];
    if (static_cast<int>(obs.descriptor.size()) != bytes) continue;
    for (std::size_t p = 0; p < predictions.size(); ++p) {
      if (!usable[p]) continue;
      const Eigen::Vector4d r = obs.z - predictions[p].z;
      if (r.dot(info[p] * r) > o.gate_chi2) continue;
      ++st.candidates_gated;
      const double d =
          descriptorDistance(norm, obs.descriptor.data(), predictions[p].descriptor.data(), bytes);
      Best& b = best[i];
      if (d < b.d1) {
        b.d2 = b.d1;
        b.d1 = d;
        b.landmark = static_cast<int>(p);
      } else if (d < b.d2) {
        b.d2 = d;
      }
    }
  }
  // Accepted pairs, best descriptor distance first; each landmark goes to one observation.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < best.size(); ++i) {
    const Best& b = best[i];
    if (b.landmark < 0 || b.d1 > o.max_descriptor_distance) continue;
    if (b.d2 < std::numeric_limits<double>::infinity() && !(b.d1 < o.dist_ratio * b.d2)) continue;
    order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return best[a].d1 < best[b].d1; });
  std::vector<bool> taken(predictions.size(), false);
  for (std::size_t i : order) {
    const std::size_t p = static_cast<std::size_t>(best[i].landmark);
    if (taken[p]) continue;
    taken[p] = true;
    (*observations)[i].type = ObservationType::kReobserved;
    (*observations)[i].landmark_id = predictions[p].landmark_id;
    ++st.associated;
  }
  if (stats) *stats = st;
  return Status::Ok();
}

}  // namespace cvslam::vision
