// Layering probe (tests/CMakeLists.txt): compiled with the coop module's include roots.
// It must NOT compile: the estimator does not see the renderer.
#include "cvslam/render/stereo_renderer.h"
