// Layering probe (tests/CMakeLists.txt): compiled with the transport nodes layer's include
// roots. It must NOT compile: the processes' adapters see no simulator.
#include "cvslam/sim/simulator.h"
