// Layering probe (tests/CMakeLists.txt): compiled with the slam module's include roots.
// It must NOT compile: the estimator does not see the simulator.
#include "cvslam/sim/simulator.h"
