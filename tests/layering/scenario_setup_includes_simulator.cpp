// Layering probe (tests/CMakeLists.txt): compiled with the scenario_setup module's include
// roots. It must NOT compile: an agent's filter start from a scenario simulates no sensor.
#include "cvslam/sim/simulator.h"
