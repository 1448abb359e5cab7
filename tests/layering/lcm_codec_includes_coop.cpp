// Layering probe (tests/CMakeLists.txt): compiled with the transport codec layer's include
// roots. It must NOT compile: the wire format knows no cooperative filter.
#include "cvslam/coop/cc_team_filter.h"
