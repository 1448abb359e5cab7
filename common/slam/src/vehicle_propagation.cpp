#include "cvslam/slam/vehicle_propagation.h"

#include <string>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/slam/linearisation_oracle.h"

namespace cvslam {

void VehiclePropagation::reset(int64_t t_us) {
  buffer_.clear();
  t_us_ = t_us;
}

Status VehiclePropagation::addImu(const ImuSample& sample) {
  if (!sample.gyro_B.allFinite() || !sample.accel_B.allFinite()) {
    return Status::Error("IMU sample at t=" + std::to_string(sample.t_us) + " µs is not finite");
  }
  if (sample.t_us <= lastSampleTime()) {
    return Status::Error("IMU sample at t=" + std::to_string(sample.t_us) +
                         " µs is not after the previous one");
  }
  if (buffer_.empty() && sample.t_us > t_us_) {
    // The state time has no sample: hold this one back to it (zero-order hold).
    ImuSample at_state = sample;
    at_state.t_us = t_us_;
    buffer_.push_back(at_state);
  }
  buffer_.push_back(sample);
  return Status::Ok();
}

Status VehiclePropagation::propagateTo(int64_t t_us, const InsPropagator& propagator,
                                       const UpdatePolicy& policy, const VariableKey& vehicle,
                                       SlamState& state, LandmarkBook& book) {
  if (t_us < t_us_) return Status::Error("frame time goes backwards");
  if (buffer_.empty() || t_us == t_us_) return Status::Ok();
  // Samples after the frame stay buffered; the frame time gets an interpolated sample.
  std::vector<ImuSample> segment;
  std::vector<ImuSample> rest;
  for (const ImuSample& s : buffer_) (s.t_us <= t_us ? segment : rest).push_back(s);
  if (segment.back().t_us < t_us) {
    ImuSample end = segment.back();
    if (!rest.empty()) {
      const ImuSample& next = rest.front();
      const double a =
          static_cast<double>(t_us - end.t_us) / static_cast<double>(next.t_us - end.t_us);
      end.gyro_B += a * (next.gyro_B - end.gyro_B);
      end.accel_B += a * (next.accel_B - end.accel_B);
    }
    end.t_us = t_us;
    segment.push_back(end);
  }
  if (segment.size() >= 2) {
    const StateVariable* v = state.find(vehicle);
    if (v == nullptr) return Status::Error("propagation: the vehicle is not in the state");
    // Φ is linearised at the current nominal; the error-state attitude part of u_v must be
    // taken there too (R̂ᵀe3 turns with every update's reset, vehicle_model::yawDirectionAt).
    const Eigen::VectorXd u_v =
        vehicle_model::yawDirectionAt(vehicle_model::pose(state, *v), book.vehicleYawDirection());
    InsTransition tr;
    if (Status s = propagator.propagate(
            state.value(*v), vehicle_model::nominalAttitude(state, vehicle), segment, &tr);
        !s.ok()) {
      return s;
    }
    Eigen::Matrix<double, 15, 1> x_true;
    if (oracle_ != nullptr && oracle_->vehicleState(segment.front().t_us, &x_true)) {
      // The ideal EKF's diagnostic: Φ and Q_d along the true state (the mean stays tr.x).
      Eigen::VectorXd x0;
      Eigen::Quaterniond q0;
      propagator.fromEulerLayout(x_true.head(propagator.stateSize()), &x0, &q0);
      InsTransition at_truth;
      if (Status s = propagator.propagate(x0, q0, segment, &at_truth); !s.ok()) return s;
      tr.Phi = at_truth.Phi;
      tr.Qd = at_truth.Qd;
    }
    if (Status s = CovarianceHelper::propagate(state, vehicle, tr.x, tr.Phi, tr.Qd, policy);
        !s.ok()) {
      return s;
    }
    vehicle_model::setNominalAttitude(state, vehicle, tr.q_BtoN);
    // Φ u_v: the transition's own image of u_v.
    book.setVehicleYawDirection(tr.Phi * u_v);
  }
  buffer_.clear();
  buffer_.push_back(segment.back());
  buffer_.insert(buffer_.end(), rest.begin(), rest.end());
  t_us_ = t_us;
  return Status::Ok();
}

}  // namespace cvslam
