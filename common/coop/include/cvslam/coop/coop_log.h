#pragma once
// The cooperation logs `agent_<id>/coop.csv` (docs/run_format.md): one row per CoopEvent;
// `agent_<id>/relations.csv`: one row per verification of a peer's frame (docs/merge.md).
// cvslam_run --mode dc and cvslam_agent write it with these two functions, so that a lockstep
// multi-process run can be compared with the in-process run byte for byte.

#include <ostream>

#include "cvslam/coop/dc_cooperation.h"

namespace cvslam::coop {

/// The header line, newline included.
const char* coopCsvHeader();

/// One event as a CSV row (time in seconds), newline included.
void writeCoopCsvRow(std::ostream& out, const CoopEvent& event);

/// `agent_<id>/relations.csv` (estimated frames only): one row per geometric verification of a
/// peer's frame and the verdict, the candidate relation x = [t_N t_E t_D ψ] (peer's frame →
/// own), √trace of its translation covariance, its yaw σ and the upper triangle of P (4×4).
const char* relationsCsvHeader();
void writeRelationsCsvRow(std::ostream& out, const RelationRecord& record);

}  // namespace cvslam::coop
