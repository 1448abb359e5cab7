#pragma once
// k-nearest landmark map management (thesis §5.8, Fig. 5.7; docs/conventions.md).
//
// At each camera epoch the state holds the k previously observed landmarks nearest to the
// virtual point m* — the point on the stereo pair's optical axis at the scene depth — plus
// the landmarks newly initialised in that epoch. Candidates are the landmarks currently in
// the state and the archived landmarks re-observed now (loop closing, §5.5.2). The rest go
// to (or stay in) the archive. With `MapKind::kFull` every landmark stays (the classical
// stochastic map) up to `max_landmarks`; beyond it the least recently observed are archived,
// so that a long flight cannot grow the O(n²) state without bound.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

class ConfigNode;
class StereoCamera;

enum class MapKind { kKNearest, kFull };

struct MapManagerOptions {
  MapKind kind = MapKind::kKNearest;  ///< `knearest` (thesis §5.8) or `full` (stochastic map)
  int k = 20;                         ///< landmarks kept besides the new ones (thesis: 20)
  double nominal_scene_depth = 10.0;  ///< depth of m* along the optical axis when no
                                      ///< landmark is observed [m]
  bool use_observed_depth = true;     ///< place m* at a quantile of the observed stereo
                                      ///< depths when there are any
  /// That quantile (0.5: the median). A camera looking down sees the ground at one depth,
  /// where any quantile will do; one looking forward sees from 2 m to the horizon, and at the
  /// median it keeps the far, poorly triangulated points and archives the near ones it has just
  /// mapped (euroc_mh03_hall: 3 of 10 seeds diverged at rest; 0.1: none; docs/filter.md
  /// "The virtual point m*").
  double scene_depth_quantile = 0.1;
  /// Full map only: at most this many landmarks in the state; beyond it the least recently
  /// observed go to the archive (0: no bound). 1 000 landmarks cost ≈ 100 ms per frame
  /// (docs/results/euroc_recorded.md "Map size").
  int max_landmarks = 1000;

  Status load(const ConfigNode& node);
};

/// A landmark competing for a place in the state.
struct MapCandidate {
  int64_t landmark_id = -1;
  Eigen::Vector3d p_LinN = Eigen::Vector3d::Zero();
  bool observed = false;  ///< observed in the current frame
  /// An archived landmark observed again (loop closing, §5.5.2): ranked before the other
  /// observed candidates, whose places it takes when more than k are observed.
  bool reactivating = false;
  int64_t last_seen_us = 0;  ///< when it was last observed (full map with max_landmarks)
};

class KNearestMapManager {
 public:
  explicit KNearestMapManager(const MapManagerOptions& options = {}) : o_(options) {}
  const MapManagerOptions& options() const { return o_; }

  /// The virtual point m* (§5.8): midway between the two optical centres, pushed along the
  /// optical axis to `depth` metres, for the vehicle at p_BinN with attitude R_BtoN.
  static Eigen::Vector3d virtualPoint(const StereoCamera& camera, const Eigen::Vector3d& p_BinN,
                                      const Eigen::Matrix3d& R_BtoN, double depth);

  /// Scene depth for m*: the median camera depth of `observed_p_LinC` when enabled and
  /// non-empty, else the nominal depth.
  double sceneDepth(const std::vector<double>& observed_depths) const;

  /// Ids of the candidates that may stay in (or enter) the state: k of them (the full map:
  /// all, or max_landmarks of them): re-observed archived candidates first, then the other
  /// observed ones, then the rest, each group by distance to m* (the full map: most recently
  /// observed first).
  /// (Departure from §5.8, which ranks by distance alone: after a long drift, m* is placed
  /// from the drifted pose and re-observed old landmarks sit metres away from it, so pure
  /// distance would keep them out of the state exactly when they could close the loop.)
  /// Ties are broken by id, so the choice is deterministic.
  std::vector<int64_t> select(const std::vector<MapCandidate>& candidates,
                              const Eigen::Vector3d& m_star) const;

 private:
  MapManagerOptions o_;
};

}  // namespace cvslam
