#include "daemon/hsad/stats_json.hpp"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace hsa::daemon {
namespace {

// Every non-empty bin as [lower_ns, upper_ns, count]; the overflow bin's upper edge is null.
nlohmann::json histogram(const LatencyHistogram::Counts& counts) {
  nlohmann::json bins = nlohmann::json::array();
  for (std::size_t b = 0; b < counts.size(); ++b) {
    if (counts[b] == 0) continue;
    const nlohmann::json upper =
        b == LatencyHistogram::kOverflowBin ? nlohmann::json(nullptr) : nlohmann::json(LatencyHistogram::upper_edge_ns(b));
    bins.push_back({LatencyHistogram::lower_edge_ns(b), upper, counts[b]});
  }
  return bins;
}

nlohmann::json percentiles(const Percentiles& p, std::int64_t max_ns) {
  return {{"p50", p.p50_ns}, {"p99", p.p99_ns}, {"p99.9", p.p999_ns}, {"max", max_ns}};
}

// The flight recorder's counts (capture_ring.hpp, capture_writer.hpp).
nlohmann::ordered_json recorder_json(const RecorderCounters& r) {
  return {{"triggers", r.ring.triggers}, {"captures", r.ring.frozen},    {"merged_triggers", r.ring.merged},
          {"dropped", r.ring.dropped},   {"files_written", r.written},   {"write_failures", r.failed},
          {"files_deleted", r.deleted},  {"bytes_written", r.bytes}};
}

}  // namespace

std::string stats_json(const RtStats& s, const RtConfig& config, const RealtimeGrant& grant,
                       const std::vector<AxisRunCounters>& axes, const std::vector<DriverRunHealth>& drivers) {
  // nlohmann::ordered_json keeps the keys in the order written here, which is the order a reader
  // of the file expects (settings, counts, distributions, counters, axes).
  nlohmann::ordered_json o;
  o["period_ns"] = config.period.count();
  o["priority"] = config.priority;
  o["cpu"] = config.cpu;
  o["sched_fifo"] = grant.sched_fifo;
  o["memory_locked"] = grant.memory_locked;
  o["cycles"] = s.cycles;
  o["overruns"] = s.overruns;
  o["skipped_periods"] = s.skipped_periods;
  o["max_overrun_streak"] = s.max_overrun_streak;
  o["lateness_ns"] = percentiles(s.lateness, s.max_lateness_ns);
  o["execution_ns"] = percentiles(s.execution, s.max_execution_ns);
  o["lateness_histogram"] = histogram(s.lateness_histogram);
  o["execution_histogram"] = histogram(s.execution_histogram);
  o["warmup_cycles"] = config.warmup_cycles;
  o["counters_linked"] = s.counters_linked;
  o["steady"] = {{"reached", s.steady},
                 {"allocations", s.steady_allocations},
                 {"deallocations", s.steady_deallocations},
                 {"locks", s.steady_locks},
                 {"minor_faults", s.steady_minor_faults},
                 {"major_faults", s.steady_major_faults}};
  o["total"] = {{"allocations", s.allocations},
                {"deallocations", s.deallocations},
                {"locks", s.locks},
                {"minor_faults", s.minor_faults},
                {"major_faults", s.major_faults}};
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const AxisRunCounters& axis : axes) {
    const AxisCounters& c = axis.counters;
    list.push_back({{"name", axis.name},
                    {"telemetry_published", c.telemetry_published},
                    {"telemetry_ring_drops", c.telemetry_ring_drops},
                    {"status_published", c.status_published},
                    {"status_ring_drops", c.status_ring_drops},
                    {"setpoints_accepted", c.setpoints_accepted},
                    {"setpoint_ring_drops", c.setpoint_ring_drops},
                    {"commands_accepted", c.commands_accepted},
                    {"command_ring_drops", c.command_ring_drops},
                    {"lcm_seq_gaps", c.lcm_seq_gaps},
                    {"rejected", c.rejected_total()},
                    {"recorder", recorder_json(axis.recorder)}});
  }
  o["axes"] = std::move(list);
  nlohmann::ordered_json driver_list = nlohmann::ordered_json::array();
  for (const DriverRunHealth& d : drivers) {
    nlohmann::ordered_json counters = nlohmann::ordered_json::object();
    for (const auto& [name, value] : d.health.counters) counters[name] = value;
    driver_list.push_back({{"name", d.name},
                           {"plugin", d.plugin},
                           {"state", d.state},
                           {"link", std::string(io::to_string(d.health.link))},
                           {"last_error", d.health.last_error},
                           {"counters", std::move(counters)}});
  }
  o["drivers"] = std::move(driver_list);
  return o.dump(2) + "\n";
}

void write_stats_json(const std::string& path, const RtStats& stats, const RtConfig& config,
                      const RealtimeGrant& grant, const std::vector<AxisRunCounters>& axes,
                      const std::vector<DriverRunHealth>& drivers) {
  std::ofstream out(path, std::ios::trunc);
  if (out) out << stats_json(stats, config, grant, axes, drivers);
  out.close();
  if (!out) {
    throw std::runtime_error("hsad: cannot write --stats-json file '" + path + "': " + std::strerror(errno));
  }
}

}  // namespace hsa::daemon
