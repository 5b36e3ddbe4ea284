#include "daemon/hsad/capture_gate.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "daemon/recorder/recorder_signals.hpp"

namespace hsa::daemon::capture_gate {
namespace {

std::string signal_names() {
  std::string names;
  for (const RecorderSignal& s : kRecorderSignals) names += (names.empty() ? "" : ", ") + std::string(s.name);
  return names;
}

}  // namespace

std::string resolve(CaptureRequest& request, const CaptureRingShape& ring) {
  if (request.action == CaptureAction::disarm) return "";
  char text[256];
  const double seconds = static_cast<double>(ring.rows) / ring.rate_hz;
  if (!std::isfinite(request.pre_s) || !std::isfinite(request.post_s)) return "capture lengths must be finite";
  std::size_t post = ring.post_rows;
  if (request.post_s >= 0.0) {
    const double rows = std::round(request.post_s * ring.rate_hz);
    if (rows > static_cast<double>(ring.rows) - 1.0) {
      std::snprintf(text, sizeof text, "post-trigger %.3g s does not fit the axis's recorder ring of %.3g s "
                    "([axes.recorder] seconds)", request.post_s, seconds);
      return text;
    }
    post = static_cast<std::size_t>(rows);
  }
  std::size_t pre = ring.rows - 1 - post;  // all the ring holds besides
  if (request.pre_s >= 0.0) {
    const double rows = std::round(request.pre_s * ring.rate_hz);
    if (rows > static_cast<double>(pre)) {
      std::snprintf(text, sizeof text, "pre-trigger %.3g s and post-trigger %.3g s do not fit the axis's recorder "
                    "ring of %.3g s ([axes.recorder] seconds): at most %.3g s before with that after",
                    request.pre_s, static_cast<double>(post) / ring.rate_hz, seconds,
                    static_cast<double>(pre) / ring.rate_hz);
      return text;
    }
    pre = static_cast<std::size_t>(rows);
  }
  int signal = -1;
  if (request.action == CaptureAction::arm) {
    const std::size_t n = ::strnlen(request.signal, sizeof request.signal);
    signal = recorder_signal_index(std::string_view(request.signal, n));
    if (signal < 0) {
      return "unknown signal '" + std::string(request.signal, n) + "': one of " + signal_names();
    }
    if (!std::isfinite(request.level)) return "the level must be a finite number";
  }
  request.signal_index = static_cast<std::int16_t>(signal);
  request.pre_rows = static_cast<std::uint32_t>(pre);
  request.post_rows = static_cast<std::uint32_t>(post);
  return "";
}

}  // namespace hsa::daemon::capture_gate
