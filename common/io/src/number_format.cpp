#include "cvslam/io/number_format.h"

#include <cstdio>
#include <cstdlib>

namespace cvslam {

std::string formatShortest(double x) {
  char buf[32];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

}  // namespace cvslam
