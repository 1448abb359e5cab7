// Layering probe (tests/CMakeLists.txt): compiled with the scenario module's include roots.
// It must NOT compile: reading a scenario needs no renderer (its `render:` section stays text).
#include "cvslam/render/world.h"
