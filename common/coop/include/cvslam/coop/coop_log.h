#pragma once
// The cooperation log `agent_<id>/coop.csv` (docs/run_format.md): one row per CoopEvent.
// cvslam_run --mode dc and cvslam_agent write it with these two functions, so that a lockstep
// multi-process run can be compared with the in-process run byte for byte.

#include <ostream>

#include "cvslam/coop/dc_cooperation.h"

namespace cvslam::coop {

/// The header line, newline included.
const char* coopCsvHeader();

/// One event as a CSV row (time in seconds), newline included.
void writeCoopCsvRow(std::ostream& out, const CoopEvent& event);

}  // namespace cvslam::coop
