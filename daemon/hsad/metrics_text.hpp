// hsad's health as Prometheus exposition text (docs/monitoring.md lists every metric): what the
// operator thread gathers every [metrics] interval_s from what hsad already keeps off the RT
// thread (the executive's snapshot, the ports' and the recorder's counters, the drivers' health,
// the operator thread's own counts), formatted by PrometheusText.
//
// Every counter is cumulative since hsad started, and every label value a counter can take is
// written from the start (0 included), so that rate() and increase() see the first fault.
//
// The RT thread's lateness goes out as a histogram, not as percentiles: Prometheus computes any
// percentile over any window from a histogram's cumulative buckets (histogram_quantile over
// rate()), and can sum the buckets of many rigs; percentiles computed here over a window of hsad's
// choosing could be neither re-windowed nor combined. Its buckets are whole bins of the executive's
// LatencyHistogram (kLatenessBucketsNs), so each is exact; the maximum goes out beside it as a
// gauge, which no histogram keeps. The executive keeps no sum of lateness: _sum is the sum of
// each bin's lower edge times its count, under the true sum by at most one bin width per sample
// (1 µs below 1 ms).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "daemon/axis/axis_port.hpp"
#include "daemon/hsad/axis_health_counts.hpp"
#include "daemon/hsad/stats_json.hpp"
#include "daemon/recorder/capture_writer.hpp"
#include "daemon/rt/realtime_grant.hpp"
#include "daemon/rt/rt_stats.hpp"
#include "daemon/supervisor/axis_state.hpp"

namespace hsa::daemon {

struct AxisMetrics {
  std::string name;
  AxisState state = AxisState::init;
  FaultReason latched = FaultReason::none;  // the latched fault, none when healthy
  AxisHealthCounts health;
  AxisCounters port;            // the LCM side's (axis_port.hpp)
  RecorderCounters recorder{};  // the flight recorder's (capture_writer.hpp)
  std::uint64_t gain_changes_applied = 0;
};

struct MetricsSnapshot {
  std::string system;       // [auth] system_name
  std::string version;      // hsad's
  bool running = true;      // false in the file written as hsad stops
  double start_time_s = 0;  // Unix time hsad started
  std::int64_t period_ns = 0;
  RealtimeGrant grant;
  RtStats rt;
  std::vector<AxisMetrics> axes;
  std::vector<DriverRunHealth> drivers;
};

// The lateness histogram's upper bounds ("le"), in ns; each is an edge of a LatencyHistogram bin.
inline constexpr std::array<std::int64_t, 17> kLatenessBucketsNs = {
    5'000,     10'000,    20'000,     50'000,     100'000,    200'000,     500'000,     1'000'000,    2'000'000,
    5'000'000, 10'000'000, 20'000'000, 40'000'000, 80'000'000, 160'000'000, 320'000'000, 1'024'000'000};

// The stable identifier of a refusal for a label ("reset_first").
[[nodiscard]] std::string_view refusal_id(Refusal refusal) noexcept;

[[nodiscard]] std::string metrics_text(const MetricsSnapshot& snapshot);

}  // namespace hsa::daemon
