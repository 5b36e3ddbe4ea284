// The gains file `hsa-analyze tune --out FILE` writes and `hsactl gains --from FILE` sends: a TOML
// document whose top-level `kp` (1/m) and `ki` (1/(m s)) are the gains; its other tables (the
// tuning's prediction) are for the reader and are not sent. hsad's gate judges the gains again.
#pragma once

#include <stdexcept>
#include <string>

namespace hsa::ctl {

struct GainsFromFile {
  double kp = 0.0;
  double ki = 0.0;
};

// Throws std::runtime_error naming the file, the line and the key: an unreadable file, a missing
// or non-numeric kp/ki, kp not > 0, ki not >= 0, or either not finite.
[[nodiscard]] GainsFromFile read_gains_file(const std::string& path);

}  // namespace hsa::ctl
