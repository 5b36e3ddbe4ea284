// hsad's run statistics as JSON, written once at exit (`hsad --stats-json FILE`), so that a script
// can set the daemon's timing beside cyclictest's (bench/latency-compare).
//
// The document holds what the exit line on stderr summarises, in full: the RT thread's settings
// and what the kernel granted; cycles, overruns and skipped periods; lateness and execution-time
// percentiles and maxima; every non-empty bin of the lateness and execution-time histograms as
// [lower_ns, upper_ns, count] (1 µs bins below 1 ms, the same resolution cyclictest reports in);
// the steady-state allocation, lock and page-fault counts of the RT cycle; and each axis's ring
// and LCM counters (telemetry published and dropped, setpoints accepted and dropped) and its
// flight recorder's (triggers, captures, merged and dropped triggers, files written, failed and
// deleted, bytes); each
// driver's state, link, last link error and error counters at the end of the run.
//
// Lateness is woke − scheduled for the absolute deadline the thread slept to with
// clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME): the quantity cyclictest measures.
#pragma once

#include <string>
#include <vector>

#include "daemon/axis/axis_port.hpp"
#include "daemon/recorder/capture_writer.hpp"
#include "daemon/rt/realtime_grant.hpp"
#include "daemon/rt/rt_config.hpp"
#include "daemon/rt/rt_stats.hpp"
#include "drivers/driver_health.hpp"

namespace hsa::daemon {

struct AxisRunCounters {
  std::string name;
  AxisCounters counters;
  RecorderCounters recorder{};  // the flight recorder's (capture_writer.hpp)
};

// A driver at the end of the run: its lifecycle state and its link's health.
struct DriverRunHealth {
  std::string name;
  std::string plugin;
  std::string state;
  io::DriverHealth health;
};

[[nodiscard]] std::string stats_json(const RtStats& stats, const RtConfig& config, const RealtimeGrant& grant,
                                     const std::vector<AxisRunCounters>& axes,
                                     const std::vector<DriverRunHealth>& drivers = {});

// Writes stats_json() to `path`. Throws std::runtime_error naming the file when it cannot.
void write_stats_json(const std::string& path, const RtStats& stats, const RtConfig& config,
                      const RealtimeGrant& grant, const std::vector<AxisRunCounters>& axes,
                      const std::vector<DriverRunHealth>& drivers = {});

}  // namespace hsa::daemon
