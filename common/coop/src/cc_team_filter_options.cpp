// CcTeamFilterOptions (config/ground_station.yaml; cc_team_filter.h).

#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/io/config_node.h"

namespace cvslam::coop {

void CcTeamFilterOptions::setJointEstimator() {
  slam.ins.attitude = vehicle::Attitude::kEuler;  // as measured (docs/results/cc_vs_dc.md)
  slam.slam.error_chart = ErrorChart::kRightInvariant;
  slam.slam.first_estimate_jacobians = false;
  slam.slam.observability_constrained = false;
  slam.slam.held_eviction = SlamOptions::HeldEviction::kNearest;  // one pool for every UAV
}

Status CcTeamFilterOptions::load(const ConfigNode& root) {
  slam.load(root);
  const ConfigNode cc = root.child("cc");
  cc.getEnum("association", association,
             {{"true_ids", CcAssociation::kTrueIds}, {"local_ids", CcAssociation::kLocalIds}});
  cc.get("image_second_order_noise", image_second_order_noise);
  cc.get("image_second_order_mean", image_second_order_mean);
  cc.get("image_pixel_sigma", image_pixel_sigma);
  cc.get("max_descriptor_distance", max_descriptor_distance);
  cc.get("association_gate_chi2", association_gate_chi2);
  cc.get("max_association_distance_m", max_association_distance_m);
  cc.get("max_vehicles", max_vehicles);
  cc.get("max_imu_gap_s", max_imu_gap_s);
  cc.get("rendezvous_min_sigma_m", rendezvous_min_sigma_m);
  cc.get("reactivation_inflation", reactivation_inflation);
  cc.get("rendezvous_sigma_ratio", rendezvous_sigma_ratio);
  cc.check(rendezvous_sigma_ratio >= 0.0, "rendezvous_sigma_ratio", "must be ≥ 0");
  cc.check(reactivation_inflation >= 0.0, "reactivation_inflation", "must be ≥ 0");
  cc.check(rendezvous_min_sigma_m >= 0.0, "rendezvous_min_sigma_m", "must be ≥ 0");
  cc.check(max_descriptor_distance >= 0.0, "max_descriptor_distance", "must be ≥ 0");
  cc.check(image_pixel_sigma > 0.0, "image_pixel_sigma", "must be > 0");
  cc.check(association_gate_chi2 > 0.0, "association_gate_chi2", "must be > 0");
  cc.check(max_association_distance_m > 0.0, "max_association_distance_m", "must be > 0");
  cc.check(max_vehicles >= 1, "max_vehicles", "must be ≥ 1");
  cc.check(max_imu_gap_s >= 0.0, "max_imu_gap_s", "must be ≥ 0");
  if (auto p = slam.filter.policy(); !p.ok()) root.check(false, "filter", p.status().message());
  return root.status();
}

Expected<CcTeamFilterOptions> CcTeamFilterOptions::loadFile(const std::string& path) {
  Expected<ConfigNode> root = ConfigNode::loadFile(path);
  if (!root.ok()) return root.status();
  CcTeamFilterOptions o;
  o.load(*root);
  root->skip("ground_station");  // the ground-station process's own section
  if (Status s = root->finish(); !s.ok()) return s;
  return o;
}

}  // namespace cvslam::coop
