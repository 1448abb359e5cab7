#pragma once
// Numbers written to text files that are read back (EuRoC sensor.yaml, calibrations): the
// shortest decimal that parses to exactly the same double, so a written file reproduces the
// run bit for bit.

#include <string>

namespace cvslam {

/// Shortest "%.Ng" (N = 15…17) that reads back to exactly x.
std::string formatShortest(double x);

}  // namespace cvslam
