#include "cvslam/coop/coop_log.h"

#include <cmath>
#include <string>

#include "cvslam/io/time_format.h"

namespace cvslam::coop {

const char* coopCsvHeader() {
  return "t,event,peer,count,fused,rejected_gate,rejected_descriptor,not_in_state,no_gain,"
         "omega1,independent,nis,nis_dof,r_scale,mapped\n";
}

void writeCoopCsvRow(std::ostream& out, const CoopEvent& e) {
  out << formatSeconds(static_cast<double>(e.t_us) * 1e-6) << ',' << coopEventName(e.kind) << ','
      << e.peer << ',' << e.count << ',' << e.fused << ',' << e.rejected_gate << ','
      << e.rejected_descriptor << ',' << e.not_in_state << ',' << (e.no_gain ? 1 : 0) << ','
      << e.omega1 << ',' << (e.independent ? 1 : 0) << ',' << e.nis << ',' << e.nis_dof << ','
      << e.r_scale << ',' << e.mapped << '\n';
}

const char* relationsCsvHeader() {
  return "t,peer,verdict,correspondences,inliers,nis,t_n,t_e,t_d,yaw,sigma_t,sigma_yaw,"
         "p00,p01,p02,p03,p11,p12,p13,p22,p23,p33,reason\n";
}

void writeRelationsCsvRow(std::ostream& out, const RelationRecord& r) {
  const merge::FrameRelation& c = r.candidate;
  std::string reason = r.reason;
  for (char& ch : reason)
    if (ch == ',' || ch == '\n') ch = ';';  // one CSV field
  // Ten significant digits, as the run records' other CSV numbers (docs/run_format.md): a
  // relation's NEES against the truth must not be the rounding's.
  const std::streamsize precision = out.precision(10);
  out << formatSeconds(static_cast<double>(r.t_us) * 1e-6) << ',' << r.peer << ',' << r.verdict
      << ',' << r.correspondences << ',' << r.inliers << ',' << r.nis << ',' << c.x(0) << ','
      << c.x(1) << ',' << c.x(2) << ',' << c.x(3) << ','
      << std::sqrt(c.P.topLeftCorner<3, 3>().trace()) << ',' << std::sqrt(c.P(3, 3)) << ',';
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) out << c.P(i, j) << ',';
  out << reason << '\n';
  out.precision(precision);
}

}  // namespace cvslam::coop
