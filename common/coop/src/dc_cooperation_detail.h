#pragma once
// Units shared by DcCooperation's source files (dc_cooperation*.cpp).

#include <cstdint>

namespace cvslam::coop::detail {

constexpr double kUsPerS = 1e6;
constexpr int kLandmarkDof = 3;

inline double seconds(int64_t dt_us) {
  return static_cast<double>(dt_us) / kUsPerS;
}

}  // namespace cvslam::coop::detail
