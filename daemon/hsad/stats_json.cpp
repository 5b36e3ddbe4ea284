#include "daemon/hsad/stats_json.hpp"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace hsa::daemon {
namespace {

// Axis names are [A-Za-z0-9_-]+ (the bridge refuses others), so they need no escaping; the check
// keeps the document valid should that rule ever change.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out + "\"";
}

const char* boolean(bool b) { return b ? "true" : "false"; }

void histogram(std::ostream& o, const LatencyHistogram::Counts& counts) {
  o << '[';
  bool first = true;
  for (std::size_t b = 0; b < counts.size(); ++b) {
    if (counts[b] == 0) continue;
    o << (first ? "" : ", ") << '[' << LatencyHistogram::lower_edge_ns(b) << ", ";
    if (b == LatencyHistogram::kOverflowBin) {
      o << "null";
    } else {
      o << LatencyHistogram::upper_edge_ns(b);
    }
    o << ", " << counts[b] << ']';
    first = false;
  }
  o << ']';
}

void percentiles(std::ostream& o, const Percentiles& p, std::int64_t max_ns) {
  o << "{\"p50\": " << p.p50_ns << ", \"p99\": " << p.p99_ns << ", \"p99.9\": " << p.p999_ns << ", \"max\": " << max_ns
    << '}';
}

}  // namespace

std::string stats_json(const RtStats& s, const RtConfig& config, const RealtimeGrant& grant,
                       const std::vector<AxisRunCounters>& axes) {
  std::ostringstream o;
  o << "{\n";
  o << "  \"period_ns\": " << config.period.count() << ",\n";
  o << "  \"priority\": " << config.priority << ",\n";
  o << "  \"cpu\": " << config.cpu << ",\n";
  o << "  \"sched_fifo\": " << boolean(grant.sched_fifo) << ",\n";
  o << "  \"memory_locked\": " << boolean(grant.memory_locked) << ",\n";
  o << "  \"cycles\": " << s.cycles << ",\n";
  o << "  \"overruns\": " << s.overruns << ",\n";
  o << "  \"skipped_periods\": " << s.skipped_periods << ",\n";
  o << "  \"max_overrun_streak\": " << s.max_overrun_streak << ",\n";
  o << "  \"lateness_ns\": ";
  percentiles(o, s.lateness, s.max_lateness_ns);
  o << ",\n  \"execution_ns\": ";
  percentiles(o, s.execution, s.max_execution_ns);
  o << ",\n  \"lateness_histogram\": ";
  histogram(o, s.lateness_histogram);
  o << ",\n  \"execution_histogram\": ";
  histogram(o, s.execution_histogram);
  o << ",\n  \"warmup_cycles\": " << config.warmup_cycles << ",\n";
  o << "  \"counters_linked\": " << boolean(s.counters_linked) << ",\n";
  o << "  \"steady\": {\"reached\": " << boolean(s.steady) << ", \"allocations\": " << s.steady_allocations
    << ", \"deallocations\": " << s.steady_deallocations << ", \"locks\": " << s.steady_locks
    << ", \"minor_faults\": " << s.steady_minor_faults << ", \"major_faults\": " << s.steady_major_faults << "},\n";
  o << "  \"total\": {\"allocations\": " << s.allocations << ", \"deallocations\": " << s.deallocations
    << ", \"locks\": " << s.locks << ", \"minor_faults\": " << s.minor_faults << ", \"major_faults\": " << s.major_faults
    << "},\n";
  o << "  \"axes\": [";
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const AxisCounters& c = axes[i].counters;
    o << (i == 0 ? "\n" : ",\n") << "    {\"name\": " << quoted(axes[i].name)
      << ", \"telemetry_published\": " << c.telemetry_published << ", \"telemetry_ring_drops\": " << c.telemetry_ring_drops
      << ", \"status_published\": " << c.status_published << ", \"status_ring_drops\": " << c.status_ring_drops
      << ", \"setpoints_accepted\": " << c.setpoints_accepted << ", \"setpoint_ring_drops\": " << c.setpoint_ring_drops
      << ", \"commands_accepted\": " << c.commands_accepted << ", \"command_ring_drops\": " << c.command_ring_drops
      << ", \"lcm_seq_gaps\": " << c.lcm_seq_gaps << ", \"rejected\": " << c.rejected_total() << '}';
  }
  o << "\n  ]\n}\n";
  return o.str();
}

void write_stats_json(const std::string& path, const RtStats& stats, const RtConfig& config,
                      const RealtimeGrant& grant, const std::vector<AxisRunCounters>& axes) {
  std::ofstream out(path, std::ios::trunc);
  if (out) out << stats_json(stats, config, grant, axes);
  out.close();
  if (!out) {
    throw std::runtime_error("hsad: cannot write --stats-json file '" + path + "': " + std::strerror(errno));
  }
}

}  // namespace hsa::daemon
