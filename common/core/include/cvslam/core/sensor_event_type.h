#pragma once
// The kinds of sensor data a vehicle produces, named once for every producer and consumer:
// the simulator's events (sim/simulator.h), the sensor streams of recorded and simulated
// datasets (sensors/sensor_stream.h), and the LCM channels that carry them
// (transport: channelStream() maps each kind to its UAV<id>/<STREAM> channel).

#include <cstdint>

namespace cvslam {

enum class SensorEventType : uint8_t {
  kImu,          ///< an inertial sample
  kGroundTruth,  ///< the true pose (simulation, or a recording's reference)
  kStereoImage,  ///< a rectified stereo image pair (CV_8UC1)
  kFeatures,     ///< a stereo feature frame (feature-level simulation: index = true landmark id)
};

}  // namespace cvslam
