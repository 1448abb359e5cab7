#pragma once
// Joint state of a stochastic map (thesis §5.5.1, eq. 5.22): vehicle block(s) plus landmarks.
//
// Each variable owns its slot (index and size) in the mean and the covariance, as in
// OpenVINS. Variables are found by key: a vehicle (one per agent, so that the
// ground station's joint filter can stack several) or a landmark (3-D point in N). Removing
// a variable compacts the indices of those after it.
//
// Only CovarianceHelper changes the covariance and the set of variables; everyone else reads
// the state and may overwrite a variable's mean (e.g. an archived landmark's re-activation
// goes through CovarianceHelper::addVariable instead).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <vector>

namespace cvslam {

/// Identifies a variable of the joint state.
///  - kVehicle: one agent's vehicle block.
///  - kLandmark: a landmark of the map (3-D point in N).
///  - kHeldLandmark: a landmark that left the map (archived, thesis §5.8) but is held in the
///    state as a Schmidt "consider" variable (Schmidt 1966; Geneva et al., ICRA 2019): its
///    cross-covariances with the rest are kept and updated, its mean and own covariance never
///    are (CovarianceHelper::update zeroes its gain), so it costs no information when it
///    comes back (landmark_lifecycle.h) and cannot be made over-confident meanwhile.
struct VariableKey {
  enum class Kind : uint8_t { kVehicle, kLandmark, kHeldLandmark };
  Kind kind = Kind::kVehicle;
  uint64_t id = 0;  ///< agent id for vehicles, landmark id for landmarks

  static VariableKey vehicle(uint64_t agent = 0) { return {Kind::kVehicle, agent}; }
  static VariableKey landmark(uint64_t landmark_id) { return {Kind::kLandmark, landmark_id}; }
  static VariableKey heldLandmark(uint64_t landmark_id) {
    return {Kind::kHeldLandmark, landmark_id};
  }
  bool operator<(const VariableKey& o) const { return kind != o.kind ? kind < o.kind : id < o.id; }
  bool operator==(const VariableKey& o) const { return kind == o.kind && id == o.id; }
};

/// Where a variable lives: rows [index, index + size) of the mean and the covariance.
struct StateVariable {
  VariableKey key;
  int index = 0;
  int size = 0;
};

/// What the covariance's error coordinates are (docs/filter.md "Invariant error chart").
///  - kAdditive: x = x̂ + δ for positions, velocities, biases and landmarks; the attitude per
///    the vehicle's parametrisation (vehicle_model.h).
///  - kRightInvariant: the same stored coordinates, but the chart of the right-invariant EKF
///    (Barrau & Bonnabel 2017): an update keeps the covariance of the invariant error
///    ξ = (ξθ, R̂ δv_B, δp + p̂ × ξθ, δl + l̂ × ξθ, δb), ξθ the rotation error about N's axes,
///    rather than the covariance of δ. In that chart the directions no observation can inform
///    (global translation and yaw) do not depend on the estimate, so a correction of the mean
///    cannot turn them into spurious information (CovarianceHelper::update).
enum class ErrorChart : uint8_t { kAdditive, kRightInvariant };

class SlamState {
 public:
  int size() const { return static_cast<int>(x_.size()); }
  const Eigen::VectorXd& mean() const { return x_; }
  const Eigen::MatrixXd& covariance() const { return P_; }

  /// Variables in index order.
  const std::vector<StateVariable>& variables() const { return vars_; }
  /// The variable's slot, or nullptr when it is not in the state. The pointer is valid until
  /// the next variable is added or removed (indices move when the state is compacted).
  const StateVariable* find(const VariableKey& key) const;
  bool has(const VariableKey& key) const { return find(key) != nullptr; }
  /// Number of variables of this kind.
  int count(VariableKey::Kind kind) const;
  /// Number of landmark variables (kLandmark; held landmarks are not counted).
  int landmarkCount() const { return count(VariableKey::Kind::kLandmark); }

  /// Mean of a variable (must be present).
  Eigen::VectorBlock<const Eigen::VectorXd> value(const StateVariable& v) const {
    return x_.segment(v.index, v.size);
  }
  /// Covariance block of a variable (must be present).
  Eigen::Block<const Eigen::MatrixXd> covarianceOf(const StateVariable& v) const {
    return P_.block(v.index, v.index, v.size, v.size);
  }
  /// Overwrites the mean of a variable (relinearisation); its covariance is untouched.
  void setValue(const StateVariable& v, const Eigen::Ref<const Eigen::VectorXd>& value) {
    x_.segment(v.index, v.size) = value;
  }

  ErrorChart errorChart() const { return chart_; }
  void setErrorChart(ErrorChart chart) { chart_ = chart; }

  /// The nominal rotation R̂ (body to N) of a vehicle whose attitude entries are a rotation
  /// error δθ, R_BtoN = R̂ Exp(δθ); nullptr for a vehicle with Euler angles (or none). Only
  /// vehicle_model and the INS read it (vehicle_model.h).
  const Eigen::Quaterniond* nominalAttitude(const VariableKey& vehicle) const;
  /// Sets (or adds) the nominal rotation of `vehicle`; marginalising the vehicle drops it.
  void setNominalAttitude(const VariableKey& vehicle, const Eigen::Quaterniond& q_BtoN) {
    nominal_[vehicle] = q_BtoN;
  }

  /// The vehicle whose rotation error a landmark's invariant error takes (ErrorChart::
  /// kRightInvariant): the vehicle it was triangulated from (CovarianceHelper::augment from a
  /// vehicle), kept through rekey; nullptr for a landmark added as an independent prior (it then
  /// takes the observing vehicle's). One fixed anchor per landmark keeps a joint state of several
  /// vehicles in one chart: the observer's would switch a landmark's chart between vehicles whose
  /// rotation errors differ (docs/results/cc_vs_dc.md "Error chart").
  const VariableKey* landmarkAnchor(const VariableKey& landmark) const;

 private:
  friend class CovarianceHelper;
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  std::vector<StateVariable> vars_;                    // index order
  std::map<VariableKey, int> slot_;                    // key -> position in vars_
  std::map<VariableKey, Eigen::Quaterniond> nominal_;  // error-state vehicles' R̂
  std::map<VariableKey, VariableKey> anchor_;          // landmark -> vehicle it was mapped from
  ErrorChart chart_ = ErrorChart::kAdditive;
};

}  // namespace cvslam
