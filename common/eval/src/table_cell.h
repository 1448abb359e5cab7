#pragma once
// One cell of the evaluation's fixed-width terminal tables: a figure with its format, or "-"
// when it does not exist (a null in the summary JSON).

#include <cstdio>
#include <optional>
#include <string>

namespace cvslam::eval_detail {

inline std::string tableCell(const std::optional<double>& x, const char* fmt) {
  if (!x) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), fmt, *x);
  return buf;
}

}  // namespace cvslam::eval_detail
