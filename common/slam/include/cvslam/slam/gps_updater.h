#pragma once
// GPS updates of a VSLAM vehicle (thesis §2.4, §3.7 — the chapter-3 GPS aiding,
// here inside the chapter-5 SLAM filter): a team can fly in and out of GPS-denied areas, the
// filter using fixes when there are any and vision alone otherwise.
//
// Observation of one fix: ins/gps_observation.h (h = [p_BinN; R_BtoN v_B], the same model as
// the chapter-3 filters), its noise the receiver's stated σ × sigma_scale. Bias columns of the
// Jacobian are zero. The position and the velocity are two observation groups, each χ² gated
// (CovarianceHelper::update). Neither the observability constraint nor first-estimate
// Jacobians apply: GPS observes exactly the global position and (through the velocity in N)
// the heading that vision cannot.

#include <Eigen/Core>

#include "cvslam/core/status.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/ins/gps_fix.h"
#include "cvslam/ins/gps_observation.h"

namespace cvslam {

class ConfigNode;

/// Config section `gps:` of agent.yaml.
struct GpsUpdateOptions {
  bool enabled = false;      ///< use GPS fixes when the sensors provide them
  bool use_velocity = true;  ///< also update with the fix's NED velocity
  /// Multiplies the receiver's stated σ. 2 by default, from the Monte-Carlo in docs/ins_gps.md
  /// ("GPS in VSLAM runs": ATE, RPE and NEES all lower than with 1): it makes up for the VSLAM
  /// filter's over-confidence in tilt (docs/filter.md), which full-weight fixes amplify.
  double sigma_scale = 2.0;

  Status load(const ConfigNode& node);
};

class GpsUpdater {
 public:
  GpsUpdater(const VariableKey& vehicle, const GpsUpdateOptions& options)
      : vehicle_(vehicle), o_(options) {}

  /// One EKF / NH∞ update of the state with `fix` (the state at the fix's time).
  Status update(SlamState& state, const GpsFix& fix, const UpdatePolicy& policy,
                UpdateReport* report);

 private:
  VariableKey vehicle_;
  GpsUpdateOptions o_;
  MeasurementBatch batch_;  // reused: no allocation per fix once warm
};

}  // namespace cvslam
