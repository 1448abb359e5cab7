#include "cvslam/coop/coop_log.h"

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

}  // namespace cvslam::coop
