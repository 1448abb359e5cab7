#pragma once
// The two-sided bound of a consistency test: the χ² 95 % band of the mean NEES of `runs`
// independent runs of `dof` degrees of freedom, [χ²₀.₀₂₅(runs·dof), χ²₀.₉₇₅(runs·dof)] / runs —
// the band scripts/mc_consistency.py applies at each time step over its runs. A test takes each
// run's NEES averaged over its frames: that average varies less than one frame's NEES does, so
// the band is wide for it and a mean outside it is an over- (above) or under-confident (below)
// filter, not chance.

#include <sstream>
#include <string>

#include "cvslam/filter/chi_square.h"

namespace cvslam::test {

struct NeesBand {
  double lo = 0.0, hi = 0.0;
  bool contains(double nees) const { return lo <= nees && nees <= hi; }
  std::string str() const {
    std::ostringstream s;
    s << "[" << lo << ", " << hi << "]";
    return s.str();
  }
};

inline NeesBand neesBand(int dof, int runs) {
  return {chiSquareQuantile(0.025, dof * runs) / runs, chiSquareQuantile(0.975, dof * runs) / runs};
}

}  // namespace cvslam::test
