#include "cvslam/io/time_format.h"

#include <cstdio>

namespace cvslam {

void appendSeconds(std::string& line, double t) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.6f", t);
  line += buf;
}

std::string formatSeconds(double t) {
  std::string s;
  appendSeconds(s, t);
  return s;
}

}  // namespace cvslam
