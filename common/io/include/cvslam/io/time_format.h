#pragma once
// Time columns of the run record (docs/run_format.md): seconds with six decimals, i.e. every
// microsecond of the dataset clock, whatever the epoch. A general-purpose format such as
// %.10g or a stream's default 6 significant digits prints a EuRoC time (≈ 1.4e9 s) as
// 1403715525 — every frame of a second on one row time.

#include <string>

namespace cvslam {

/// `t` [s] as "%.6f" (e.g. 1403715273.262143, 0.050000).
std::string formatSeconds(double t);

/// Appends formatSeconds(t) to `line` (no allocation beyond the line's own growth).
void appendSeconds(std::string& line, double t);

}  // namespace cvslam
