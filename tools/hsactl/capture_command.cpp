#include "tools/hsactl/capture_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <thread>

#include "daemon/recorder/recorder_signals.hpp"
#include "tools/hsactl/axis_commands.hpp"
#include "tools/hsactl/interrupt.hpp"

namespace hsa::ctl {

std::string capture_options_error(const CaptureOptions& o) {
  if (o.disarm) {
    if (!o.signal.empty() || o.above || o.below || o.pre_s >= 0.0 || o.post_s >= 0.0 || o.repeat) {
      return "--disarm takes no other option";
    }
    return "";
  }
  if (!std::isfinite(o.pre_s) || !std::isfinite(o.post_s)) return "--pre and --post must be finite";
  if (o.signal.empty()) {
    if (o.above || o.below || o.repeat) return "--above, --below and --repeat need --when SIGNAL";
    return "";
  }
  if (daemon::recorder_signal_index(o.signal) < 0) {
    std::string names;
    for (const daemon::RecorderSignal& s : daemon::kRecorderSignals) names += (names.empty() ? "" : ", ") + std::string(s.name);
    return "--when: unknown signal '" + o.signal + "': one of " + names;
  }
  if (o.above.has_value() == o.below.has_value()) return "--when needs one of --above LEVEL or --below LEVEL";
  const double level = o.above ? *o.above : *o.below;
  if (!std::isfinite(level)) return "the level must be a finite number";
  return "";
}

std::string scope_command_line_error(bool live, bool has_file, bool now, const CaptureOptions& o) {
  if (!live && !has_file) return "scope: give FILE.mat, or --live AXIS";
  if (!live && (!o.signal.empty() || o.pre_s >= 0 || o.post_s >= 0)) return "scope: --when, --pre and --post go with --live AXIS";
  if (live && o.signal.empty() && !now) return "scope --live: give --now, or a condition (--when SIGNAL --above|--below LEVEL)";
  return "";
}

int request_capture(LcmSession& session, const CaptureOptions& o) {
  const std::int8_t action = o.disarm ? hsa::command_t::CAPTURE_DISARM
                             : o.signal.empty() ? hsa::command_t::CAPTURE_NOW
                                                : hsa::command_t::CAPTURE_ARM;
  const auto send = [&] {
    return session.send(hsa::command_t::CAPTURE, [&](hsa::command_t& m) {
      m.capture_action = action;
      m.capture_pre_s = o.pre_s;
      m.capture_post_s = o.post_s;
      if (action == hsa::command_t::CAPTURE_ARM) {
        m.capture_signal = o.signal;
        m.capture_below = o.below.has_value();
        m.capture_level = o.below ? *o.below : *o.above;
        m.capture_repeat = o.repeat;
      }
    });
  };
  if (const int code = carry_out(session, send, "capture"); code != 0) return code;
  const std::string& axis = session.axis();
  if (action == hsa::command_t::CAPTURE_NOW) {
    std::printf("%s: capture taken%s\n", axis.c_str(), session.unverified_tag());
  } else if (action == hsa::command_t::CAPTURE_DISARM) {
    std::printf("%s: flight recorder condition disarmed%s\n", axis.c_str(), session.unverified_tag());
  } else {
    // What hsad armed, as its status says (a single-shot condition may have fired already).
    session.poll(std::chrono::milliseconds(150));
    const std::string& armed = session.status()->capture_condition;
    std::printf("%s: armed: %s%s\n", axis.c_str(), armed.empty() ? "(fired already)" : armed.c_str(),
                session.unverified_tag());
  }
  return 0;
}

namespace {

// The capture files of `axis` in `folder` (named <axis>-<time>-<reason>.mat, complete: not .part).
std::vector<std::string> captures_of(const std::string& folder, const std::string& axis) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(axis + "-") && name.ends_with(".mat")) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

CaptureFolderSnapshot snapshot_captures(const std::string& folder, const std::string& axis) {
  return {folder, axis, captures_of(folder, axis)};
}

std::optional<std::string> wait_for_new_capture(const CaptureFolderSnapshot& since, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!interrupted) {
    std::vector<std::string> fresh;
    for (const std::string& name : captures_of(since.folder, since.axis)) {
      if (!std::binary_search(since.before.begin(), since.before.end(), name)) fresh.push_back(name);
    }
    // Names sort by the trigger's time: the newest is the last.
    if (!fresh.empty()) return (std::filesystem::path(since.folder) / fresh.back()).string();
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return std::nullopt;
}

int live_scope(LcmSession& session, const CaptureOptions& o, const std::string& folder, double timeout_s,
               const std::function<int(const std::string&)>& draw) {
  const std::string& axis = session.axis();
  // The files present now: the capture is the one that appears after the trigger.
  const CaptureFolderSnapshot before = snapshot_captures(folder, axis);
  if (const int code = request_capture(session, o); code != 0) return code;
  std::fprintf(stderr, "hsactl: scope --live: waiting up to %.0f s for the capture in %s\n", timeout_s, folder.c_str());
  const std::optional<std::string> file = wait_for_new_capture(before, timeout_s);
  if (!file) {
    std::fprintf(stderr, "hsactl: scope --live: no new capture of axis '%s' in %s within %.0f s%s\n", axis.c_str(),
                 folder.c_str(), timeout_s,
                 interrupted ? " (interrupted)" : " (did the condition fire? is this hsad's folder?)");
    return 1;
  }
  std::fprintf(stderr, "hsactl: scope --live: %s\n", file->c_str());
  try {
    return draw(*file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hsactl: %s\n", e.what());
    return 2;
  }
}

}  // namespace hsa::ctl
