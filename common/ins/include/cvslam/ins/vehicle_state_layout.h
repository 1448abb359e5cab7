#pragma once
// Layout of the vehicle part of the state vector (thesis §2.3, §5.3; docs/conventions.md):
//   x_v = [X Y Z | U V W | attitude | (b_a xyz | b_g xyz)]
// NED position [m], body-frame velocity [m/s], three attitude entries [rad], and optionally
// accelerometer and gyro biases (beyond the thesis; needed for real IMUs).
// The attitude entries are read per `Attitude` (docs/filter.md): the thesis's ZYX Euler
// angles φ θ ψ, or a rotation error δθ about a nominal rotation R̂ kept beside the state,
// R_BtoN = R̂ · Exp(δθ) (body-frame perturbation), zero after every correction.

namespace cvslam::vehicle {

constexpr int kPosition = 0;       ///< p_BinN: X Y Z, NED [m]
constexpr int kVelocity = 3;       ///< v_B: U V W, body frame [m/s]
constexpr int kAttitude = 6;       ///< φ θ ψ, or δθ [rad] (see Attitude)
constexpr int kAccelBias = 9;      ///< b_a [m/s²] (only with bias states)
constexpr int kGyroBias = 12;      ///< b_g [rad/s] (only with bias states)
constexpr int kSizeNoBias = 9;     ///< thesis vehicle state
constexpr int kSizeWithBias = 15;  ///< with IMU bias states

/// How the attitude entries are read (`ins.attitude`).
enum class Attitude {
  kErrorState,  ///< δθ about a nominal rotation: no singularity, any IMU mounting
  kEuler,       ///< ZYX Euler angles (thesis eq. 2.4), singular at pitch ±90° (the default)
};

constexpr int size(bool with_bias) {
  return with_bias ? kSizeWithBias : kSizeNoBias;
}

}  // namespace cvslam::vehicle
