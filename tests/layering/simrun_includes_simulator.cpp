// Layering probe (tests/CMakeLists.txt), the control: the simulation drivers may use the
// simulator, the renderer and the estimator, so this compiles. It shows that the probes
// that must fail fail for the layering, not for a broken probe.
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/sim/simulator.h"
#include "cvslam/slam/visual_inertial_slam.h"
