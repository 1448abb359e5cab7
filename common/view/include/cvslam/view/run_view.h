#pragma once
// A finished run folder (docs/run_format.md) as cvslam_view shows it (`cvslam_view --run DIR`):
// the same JSON a live client gets on connecting (team_view.h), for the whole run at once, so
// the page replays it with a time slider. Per UAV: states.csv (else trajectory.tum, without
// covariance), truth.csv for NEES, stats.json for latency and landmark counts, the final
// landmarks.csv (drawn as the final map), coop.csv exchanges as links; the ground station's
// joint map when DIR/ground_station/landmarks.csv exists.

#include <string>

#include "cvslam/core/status.h"
#include "cvslam/io/json_file.h"
#include "cvslam/view/team_view.h"

namespace cvslam::view {

/// The run as one JSON document ("live": false, "t0"/"t1" the time span). Fails with a clear
/// message when DIR is not a run folder.
Expected<Json> runViewJson(const std::string& run_dir, const TeamViewOptions& options = {});

}  // namespace cvslam::view
