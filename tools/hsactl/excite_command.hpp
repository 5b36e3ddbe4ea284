// `hsactl excite`: a closed-loop identification run made by hsad (command_t.EXCITE; Puglisi et
// al. 2015, section 3.1.1). hsad's RT loop adds a seeded PRMS or PRBS to the working point and
// follows it with P control for the duration, then holds the working point with its PI gains back;
// hsactl sends one command, records the run's telemetry (the samples hsad marks `exciting`) to the
// CSV of `hsactl record`, which `hsa-analyze identify` reads, and waits for the end.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

struct ExciteOptions {
  std::optional<double> working_point_m;  // none: where the rod is
  double amplitude_m = 1e-3;
  double switching_s = 0.3;
  int levels = 5;       // PRMS levels over ±amplitude
  bool prbs = false;    // a PRBS (±amplitude) instead of a PRMS
  double duration_s = 20.0;
  std::int64_t seed = 1;
  double kp_per_m = 200.0;  // 0.2 per mm
  std::string record_path;  // "": do not record
};

// 0 when the excitation ran its duration with the axis ENABLED (and, with a record, at least one
// sample was written); 1 with hsad's reason when it was refused, or when a fault, a disable or
// another command ended it early (the faults printed); 2 when the record cannot be written or no
// status comes; 130 on Ctrl-C, which ends the excitation (a MODE position command: the axis then
// holds the working point). The wait is bounded by the duration plus 5 s.
int excite(LcmSession& session, const ExciteOptions& options);

}  // namespace hsa::ctl
