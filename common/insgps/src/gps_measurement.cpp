#include "cvslam/insgps/gps_measurement.h"

#include "cvslam/geometry/euler.h"
#include "cvslam/ins/gps_observation.h"

namespace cvslam::insgps {

StateVector stateDifference(const StateVector& a, const StateVector& b) {
  StateVector d = a - b;
  for (int i = 0; i < 3; ++i) d(vehicle::kAttitude + i) = wrapAngle(d(vehicle::kAttitude + i));
  return d;
}

StateVector wrapYaw(StateVector x) {
  x(vehicle::kAttitude + 2) = wrapAngle(x(vehicle::kAttitude + 2));
  return x;
}

MeasVector gpsPredicted(const StateVector& x) {
  return cvslam::gpsPrediction(EstimatedPose::fromEuler(x));
}

MeasJacobian gpsJacobian(const StateVector& x) {
  return cvslam::gpsJacobian(EstimatedPose::fromEuler(x));
}

MeasVector gpsMeasurement(const GpsFix& fix) {
  return cvslam::gpsMeasurement(fix);
}

MeasMatrix gpsCovariance(const GpsFix& fix) {
  return cvslam::gpsCovariance(fix);
}

}  // namespace cvslam::insgps
