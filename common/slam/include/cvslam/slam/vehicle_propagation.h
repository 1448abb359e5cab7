#pragma once
// Step 1 of the recipe (visual_inertial_slam.h) for one vehicle of a SlamState: its IMU buffer
// and its propagation to a frame time (thesis §5.3). Shared by VisualInertialSlam and the
// ground station's joint filter (coop/cc_team_filter.h), whose vehicles each have one.
//
// The buffer's front() is at the vehicle's state time: the first sample after it is held back
// to that time (zero-order hold). propagateTo runs the InsPropagator over the samples up to
// the target time (an interpolated sample at the target when a later one is buffered, else the
// last one held) and CovarianceHelper::propagate on the vehicle's block: cross-covariances with
// every other variable of the state follow; the book's u_v follows Φ.

#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/slam/landmark_book.h"

namespace cvslam {

class LinearisationOracle;

class VehiclePropagation {
 public:
  /// Empties the buffer; the vehicle's state is at t_us.
  void reset(int64_t t_us);
  /// Buffers a sample: finite, after the previous one (or the state time).
  Status addImu(const ImuSample& sample);
  /// Propagates `vehicle` of `state` to t_us (≥ time()).
  Status propagateTo(int64_t t_us, const InsPropagator& propagator, const UpdatePolicy& policy,
                     const VariableKey& vehicle, SlamState& state, LandmarkBook& book);
  /// Time of the last buffered sample (time() − 1 µs when none): addImu takes later ones only.
  int64_t lastSampleTime() const { return buffer_.empty() ? t_us_ - 1 : buffer_.back().t_us; }
  /// Whether a sample is buffered (lastSample() is valid).
  bool hasSamples() const { return !buffer_.empty(); }
  /// The last buffered sample (hasSamples()).
  const ImuSample& lastSample() const { return buffer_.back(); }
  /// The vehicle's state time.
  int64_t time() const { return t_us_; }
  /// Φ and Q_d at the truth (linearisation_oracle.h; simulation diagnostics); null: off.
  void setOracle(const LinearisationOracle* oracle) { oracle_ = oracle; }

 private:
  std::vector<ImuSample> buffer_;  // front() is at the state time
  int64_t t_us_ = 0;
  const LinearisationOracle* oracle_ = nullptr;
};

}  // namespace cvslam
