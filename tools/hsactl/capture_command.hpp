// `hsactl capture AXIS` and `hsactl scope --live AXIS`: the flight recorder's triggers an operator
// sets (command_t.CAPTURE; docs/flight-recorder.md, Triggers). A capture now; a condition on one
// of a capture file's signals (`--when following_error_m --above 0.001`), single-shot or repeated;
// or disarming it. hsactl checks what it can before sending (a known signal, a finite level, one
// crossing); hsad judges the lengths against the axis's ring and answers with its reason.
//
// `scope --live` arms such a trigger (or takes a capture now), waits, bounded, for the new capture
// file of the axis to appear in the capture folder (on this machine), and returns its path, which
// the caller draws as `hsactl scope FILE.mat` does.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

struct CaptureOptions {
  double pre_s = -1.0;   // < 0: the axis's ring default
  double post_s = -1.0;
  std::string signal;    // --when: a condition; empty: a capture now (or --disarm)
  std::optional<double> above, below;
  bool repeat = false;   // --repeat; else single-shot
  bool disarm = false;
};

// What is wrong with `o` before anything is sent ("" when nothing is): a signal a capture file
// does not have (with those it has), a missing, doubled or non-finite level, a level without
// --when, --disarm with anything else, a negative length.
[[nodiscard]] std::string capture_options_error(const CaptureOptions& o);

// What is wrong with a `scope` command line ("" when nothing is): FILE.mat or --live, and with
// --live, --now or a condition (`now`: --now given).
[[nodiscard]] std::string scope_command_line_error(bool live, bool has_file, bool now, const CaptureOptions& o);

// Sends the CAPTURE command and waits for the axis's answer; prints what it did. The exit code.
int request_capture(LcmSession& session, const CaptureOptions& o);

// The newest capture file of `axis` in `folder` that appeared after `since` (a list of names
// taken before), within `timeout_s`; nullopt on timeout or Ctrl-C.
struct CaptureFolderSnapshot {
  std::string folder;
  std::string axis;
  std::vector<std::string> before;  // capture files of the axis present then
};
[[nodiscard]] CaptureFolderSnapshot snapshot_captures(const std::string& folder, const std::string& axis);
[[nodiscard]] std::optional<std::string> wait_for_new_capture(const CaptureFolderSnapshot& since, double timeout_s);

// scope --live: sends the trigger, waits for its file in `folder` (at most timeout_s) and hands it
// to `draw` (which throws on a file it cannot draw). The exit code: 1 when no capture came.
int live_scope(LcmSession& session, const CaptureOptions& o, const std::string& folder, double timeout_s,
               const std::function<int(const std::string&)>& draw);

}  // namespace hsa::ctl
