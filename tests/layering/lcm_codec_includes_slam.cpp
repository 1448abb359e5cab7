// Layering probe (tests/CMakeLists.txt): compiled with the LCM codec layer's include roots.
// It must NOT compile: the wire format does not see the estimator.
#include "cvslam/lcm/codec.h"
#include "cvslam/slam/visual_inertial_slam.h"
