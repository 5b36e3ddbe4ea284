// hsad: runs the hydraulic servo-actuator loops of the configured axes on one SCHED_FIFO thread.
//
//   hsad --config FILE [--duration S] [--stats-json OUT] [--lock-dir DIR] [--key-dir DIR]
//                                         run (until a stop signal, or for S seconds); at exit
//                                         write the RT statistics to OUT (stats_json.hpp)
//   hsad --check-config FILE [--key-dir DIR] [--lock-dir DIR]
//                                         refuse what the start would refuse before it opens a
//                                         device (each driver's settings and plan, the locks, the
//                                         operator keys, the axes' bindings and loops), with the
//                                         start's words; else print the summary
//
// Start-up order matters for the real-time rules (docs/architecture.md): everything the RT thread touches is
// built first (drivers loaded, configured and activated, signals bound, loops constructed); then
// the RT thread is created, and only then the LCM bridge's thread, the watchdog's, the flight
// recorder's writer and, with [metrics], the metrics textfile's writer (the threads
// the drivers and LCM start for themselves, a Modbus bus thread, a socketcan watchdog, LCM's
// receive threads, already run; none touches what the RT thread touches). Before any of it, and before any device is opened, hsad asks each plugin for its plan
// (the devices it would open, the channels it would declare), locks its configuration, axes and
// devices (instance_lock.hpp), so that a second hsad on them refuses to start, and makes the checks
// `--check-config` makes (startup_check.hpp), in the same order and words. Shutdown reverses it: the RT thread stops, one last cycle disables every axis so the
// valves are safe, and the drivers deactivate (outputs to their safe values). Exit code 0.
#include <CLI/CLI.hpp>
#include <signal.h>
#include <unistd.h>
#include <time.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "daemon/config/describe.hpp"
#include "daemon/config/load_config.hpp"
#include "daemon/hsad/axis_setup.hpp"
#include "daemon/hsad/daemon_cycle.hpp"
#include "daemon/hsad/driver_set.hpp"
#include "daemon/hsad/instance_lock.hpp"
#include "daemon/hsad/metrics_textfile.hpp"
#include "daemon/hsad/operator_service.hpp"
#include "daemon/hsad/startup_check.hpp"
#include "daemon/hsad/stats_json.hpp"
#include "daemon/lcm_bridge/lcm_bridge.hpp"
#include "daemon/recorder/capture_writer.hpp"
#include "daemon/rt/housekeeping_affinity.hpp"
#include "daemon/rt/rt_executive.hpp"
#include "daemon/service/systemd_watchdog.hpp"
#include "daemon/axis/axis_signals.hpp"
#include "drivers/clock.hpp"
#include "msgs/auth/operator_key.hpp"
#include "msgs/auth/status_mac.hpp"

namespace hsa::daemon {
namespace {

// The operators' keys when the configuration requires authentication (none otherwise). Throws
// msgs::KeyFileError naming the file and what is wrong with it.
AuthConfig operator_keys(const AuthSettings& settings) {
  AuthConfig auth;
  auth.required = settings.require_auth;
  auth.stamp_window_s = settings.stamp_window_s;
  auth.system = settings.system_name;
  if (auth.required) auth.keys = msgs::read_key_dir(settings.key_dir);
  if (auth.keys.size() > msgs::kMaxStatusMacs) {
    throw msgs::KeyFileError(settings.key_dir + " holds " + std::to_string(auth.keys.size()) +
                             " operator keys; hsad signs each status for every key it holds, at most " +
                             std::to_string(msgs::kMaxStatusMacs) + ": remove the keys of operators who left");
  }
  return auth;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += (text.empty() ? "" : "\n") + line;
  return text;
}

// How a refused key file reads, from the start and from the check alike.
std::string key_refusal(const std::string& config_path, const msgs::KeyFileError& e) {
  return config_path + ": [auth] operator keys: " + e.what();
}

// `hsad --check-config`: every refusal the start would make before it opens a device, in the
// start's words (run() makes the same checks in the same order); none when the start would go on.
std::vector<std::string> check(const DaemonConfig& config, const std::string& lock_dir) {
  const DriverPlans plans = plan_drivers(config);
  std::vector<std::string> refused = plans.refused;
  if (plans.refused.empty()) {
    if (std::string held = held_resource(lock_dir, resources_of(config, plans.drivers)); !held.empty()) {
      refused.push_back(std::move(held));
    }
  }
  try {
    (void)operator_keys(config.auth);
  } catch (const msgs::KeyFileError& e) {
    refused.push_back(key_refusal(config.source, e));
  }
  if (plans.refused.empty()) {
    try {
      check_axes(config, plans.drivers);
    } catch (const std::exception& e) {
      refused.push_back(e.what());
    }
  }
  return refused;
}

std::string operator_names(const AuthConfig& auth) {
  std::string names;
  for (const auto& k : auth.keys) names += (names.empty() ? "" : ", ") + k.operator_id;
  return names;
}

LcmBridgeConfig bridge_config(const DaemonConfig& config, AuthConfig auth) {
  LcmBridgeConfig b;
  b.lcm_url = config.lcm_url;
  b.auth = std::move(auth);
  b.lease_timeout_s = config.auth.lease_timeout_s;
  for (const AxisConfig& a : config.axes) {
    AxisLimits limits;
    limits.min_position_m = a.limits.min_m;
    limits.max_position_m = a.limits.max_m;
    limits.max_velocity_m_s = a.law->max_speed_m_s();  // finite: the config requires it
    b.axes.push_back({a.name, limits});
  }
  return b;
}

// What each axis's capture files say beside its rows.
std::vector<CaptureWriter::Axis> capture_axes(const DaemonConfig& config,
                                              const std::vector<std::unique_ptr<AxisRuntime>>& axes,
                                              std::int64_t epoch_ns) {
  std::vector<CaptureWriter::Axis> out;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    out.push_back({&axes[i]->recorder->ring(),
                   {config.axes[i].name, config.text, config.axes[i].law->describe(), config.realtime.base_rate_hz(),
                    epoch_ns}});
  }
  return out;
}

// The recorder's folder at start: a folder it cannot write to is said now, not at the first fault
// (which would then go unrecorded all the same: the loop runs on).
void report_recorder(const CaptureWriter& recorder, const DaemonConfig& config) {
  const std::string folder = recorder.folder().string();
  const bool writable = access(folder.c_str(), W_OK | X_OK) == 0;
  std::fprintf(stderr, "hsad: flight recorder: %.1f s per axis at %.0f Hz, captures of every fault into %s%s\n",
               config.axes.front().recorder.seconds, config.realtime.base_rate_hz(), folder.c_str(),
               writable ? "" : (std::string(" (WARNING: not writable: ") + std::strerror(errno) + ")").c_str());
}

// The metrics as the operator thread sees them now, with the recorder's counters and the daemon's
// own; `running` is false in the file hsad leaves as it stops.
MetricsSnapshot metrics_now(const OperatorService& operators, const CaptureWriter& recorder, const LcmBridge& bridge,
                            double start_time_s, bool running) {
  MetricsSnapshot m = operators.metrics_snapshot();
  m.system = bridge.system();
  m.version = HSA_VERSION;
  m.start_time_s = start_time_s;
  m.running = running;
  for (std::size_t i = 0; i < m.axes.size(); ++i) m.axes[i].recorder = recorder.counters(i);
  return m;
}

RtConfig rt_config(const RealtimeConfig& r) {
  RtConfig c;
  c.priority = r.priority;
  c.cpu = r.cpu;
  c.require_realtime = r.require_realtime;
  c.period = std::chrono::microseconds(r.base_period_us);
  c.stack_prefault_bytes = std::size_t{r.stack_prefault_kib} * 1024;
  return c;
}

void print_stats(const RtStats& s) {
  std::fprintf(stderr,
               "hsad: %llu cycles, %llu overruns (%llu periods skipped, longest streak %llu); lateness p50 %.1f µs, p99 %.1f µs, "
               "p99.9 %.1f µs, max %.1f µs; steady-state RT allocations %llu, locks %llu, page faults %llu "
               "minor / %llu major%s\n",
               static_cast<unsigned long long>(s.cycles), static_cast<unsigned long long>(s.overruns),
               static_cast<unsigned long long>(s.skipped_periods),
               static_cast<unsigned long long>(s.max_overrun_streak), s.lateness.p50_ns / 1e3, s.lateness.p99_ns / 1e3,
               s.lateness.p999_ns / 1e3, s.max_lateness_ns / 1e3,
               static_cast<unsigned long long>(s.steady_allocations), static_cast<unsigned long long>(s.steady_locks),
               static_cast<unsigned long long>(s.steady_minor_faults),
               static_cast<unsigned long long>(s.steady_major_faults),
               s.counters_linked ? "" : " (allocation/lock counters not linked in this build)");
}

// Every signal whose default action ends the process without hsad's safe shutdown, except the
// ones that report a fault of hsad itself (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT: the process
// cannot be trusted to run on) and SIGKILL/SIGSTOP, which cannot be caught. The device-side
// watchdog covers those (docs/safety.md).
constexpr int kStopSignals[] = {SIGTERM, SIGINT, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2};

int run(const DaemonConfig& config, double duration_s, const std::string& stats_json_path,
        const std::string& lock_dir) {
  // Stop signals are taken synchronously by the main thread; every thread created below inherits
  // the mask, so none of them ever interrupts the RT thread. SIGPIPE is ignored: a write to a
  // closed socket fails with EPIPE, which the writer handles.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  for (const int sig : kStopSignals) sigaddset(&stop_signals, sig);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);

  // Before any other thread exists (the drivers' bus threads start below): they inherit this.
  if (config.realtime.isolate_cpu && config.realtime.cpu >= 0) {
    const HousekeepingAffinity h = keep_off_rt_cpu(config.realtime.cpu);
    if (h.applied) {
      std::fprintf(stderr, "hsad: RT CPU %d is the RT thread's; the other threads run on CPUs %s\n",
                   config.realtime.cpu, h.cpus.c_str());
    } else {
      std::fprintf(stderr, "hsad: the other threads share RT CPU %d: %s\n", config.realtime.cpu, h.reason.c_str());
    }
  }

  // What needs no device first, in the order `hsad --check-config` checks it (check below): the
  // plugins' plans (which also name the devices to lock), the lock, the keys, the axes.
  const DriverPlans plans = plan_drivers(config);
  if (!plans.refused.empty()) throw std::runtime_error(joined(plans.refused));
  const InstanceLock lock(lock_dir, resources_of(config, plans.drivers));
  AuthConfig auth = operator_keys(config.auth);
  check_axes(config, plans.drivers);
  if (auth.required) {
    std::fprintf(stderr, "hsad: commands are authenticated; operators: %s\n", operator_names(auth).c_str());
  } else {
    std::fprintf(stderr, "hsad: WARNING: %s\n", kAuthOffWarning);
  }
  DriverSet drivers(config);
  LcmBridge bridge(bridge_config(config, std::move(auth)));
  std::vector<std::unique_ptr<AxisRuntime>> axes;
  const std::vector<io::DriverHandle*> handles = drivers.handles();
  for (std::size_t i = 0; i < config.axes.size(); ++i) {
    const AxisConfig& a = config.axes[i];
    const AxisParams params = axis_params(a, config.realtime);
    auto loop = std::make_unique<AxisLoop>(params, bind_axis_signals(a.name, params.bindings, handles));
    axes.push_back(std::make_unique<AxisRuntime>(std::move(loop), bridge.axis(i), drivers.mask_of(drivers_of(a))));
    axes.back()->telemetry = TickDecimator(a.ticks_per_telemetry);
    // Both of its buffers are written here, before the RT thread and mlockall (capture_ring.hpp).
    axes.back()->recorder = std::make_unique<AxisRecorder>(
        std::make_unique<CaptureRing>(a.recorder.rows, a.recorder.post_rows));
  }
  drivers.activate_all();

  SystemdWatchdog watchdog;
  // Pinged only while the RT cycles come within the tightest blind-time bound of the axes.
  double max_gap_s = 1.0;
  for (const AxisConfig& a : config.axes) max_gap_s = std::min(max_gap_s, a.safety.max_blind_time_s);
  watchdog.set_max_gap(std::chrono::nanoseconds(static_cast<std::int64_t>(max_gap_s * 1e9)));
  DaemonCycle cycle(drivers, axes, watchdog);
  CaptureWriter recorder(recorder_folder(config.recorder), {config.recorder.max_files, config.recorder.max_bytes},
                         capture_axes(config, axes, cycle.epoch_ns()));
  const RtConfig rt = rt_config(config.realtime);
  RtExecutive executive(rt, cycle);
  const RealtimeGrant grant = executive.start();  // the RT thread: before the bridge's and the watchdog's
  bridge.start();
  watchdog.start();
  recorder.start();
  report_recorder(recorder, config);
  OperatorService operators(axes, drivers, executive, rt, grant);
  // The Prometheus textfile: its own thread formats and writes what the operator thread gathers.
  const double start_time_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::unique_ptr<MetricsTextfile> metrics;
  if (config.metrics.enabled()) {
    metrics = std::make_unique<MetricsTextfile>(config.metrics.textfile);
    metrics->start();
    std::fprintf(stderr, "hsad: metrics: %s every %g s\n", config.metrics.textfile.c_str(), config.metrics.interval_s);
  }
  const auto metrics_interval = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(config.metrics.interval_s));
  operators.attach_recorder(&recorder);

  std::fprintf(stderr, "hsad: %zu axis(es) running at %.0f Hz on %s; SCHED_FIFO %s, memory %s\n", axes.size(),
               config.realtime.base_rate_hz(), bridge.lcm_url().c_str(), grant.sched_fifo ? "granted" : "refused",
               grant.memory_locked ? "locked" : "not locked");
  std::fprintf(stderr, "hsad: system '%s', instance %016llx: commands signed for another daemon are refused\n",
               bridge.system().c_str(), static_cast<unsigned long long>(bridge.instance()));
  watchdog.notify_ready(std::to_string(axes.size()) + " axis(es) running");

  const auto started = std::chrono::steady_clock::now();
  auto next_metrics = started;
  const timespec tick{0, 10'000'000};  // 10 ms: commands and status at 100 Hz
  for (;;) {
    const int sig = sigtimedwait(&stop_signals, nullptr, &tick);
    if (sig > 0) {
      std::fprintf(stderr, "hsad: SIG%s: stopping\n", sigabbrev_np(sig));
      break;
    }
    operators.poll();
    if (metrics && std::chrono::steady_clock::now() >= next_metrics) {
      metrics->post(metrics_now(operators, recorder, bridge, start_time_s, true));
      next_metrics = std::chrono::steady_clock::now() + metrics_interval;
    }
    if (duration_s > 0 &&
        std::chrono::steady_clock::now() - started >= std::chrono::duration<double>(duration_s)) {
      std::fprintf(stderr, "hsad: ran for %.1f s: stopping\n", duration_s);
      break;
    }
  }

  watchdog.notify_stopping();
  executive.stop();
  recorder.stop();  // writes a capture frozen before the RT thread stopped
  cycle.drive_safe(io::monotonic_ns());
  operators.poll();  // the final (disabled) status
  if (metrics) metrics->stop(metrics_now(operators, recorder, bridge, start_time_s, false));
  bridge.stop();     // flushes what is in its rings
  watchdog.stop();
  std::vector<DriverRunHealth> driver_health;  // before deactivation closes the links
  for (const io::DriverHandle* d : drivers.handles()) {
    driver_health.push_back({d->name(), d->plugin().name(), std::string(io::to_string(d->state())), d->health()});
  }
  drivers.deactivate_all();
  const RtStats stats = executive.snapshot();
  print_stats(stats);
  if (!stats_json_path.empty()) {
    std::vector<AxisRunCounters> counters;
    for (std::size_t i = 0; i < bridge.axis_count(); ++i) {
      counters.push_back({bridge.axis(i).name(), bridge.axis(i).counters(), recorder.counters(i)});
    }
    write_stats_json(stats_json_path, stats, rt, grant, counters, driver_health);
  }
  return 0;
}

}  // namespace
}  // namespace hsa::daemon

int main(int argc, char** argv) {
  CLI::App app{"hsad: hydraulic servo-actuator controller (real-time loops, LCM interface)"};
  app.set_version_flag("--version", "hsad " HSA_VERSION);
  std::string config_path, check_path, stats_json_path, lock_dir = hsa::daemon::kDefaultLockDir, key_dir;
  double duration_s = 0.0;
  auto* run_opt = app.add_option("--config", config_path, "configuration file (TOML)");
  auto* check_opt = app.add_option("--check-config", check_path, "validate a configuration file and exit");
  app.add_option("--duration", duration_s, "stop after this many seconds (0: run until SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--stats-json", stats_json_path,
                 "at exit, write the RT statistics (lateness histogram, percentiles, overruns, steady-state "
                 "counters) to this file as JSON");
  app.add_option("--lock-dir", lock_dir,
                 "directory of the locks that keep a second hsad off the same configuration, axes and I/O")
      ->capture_default_str();
  app.add_option("--key-dir", key_dir,
                 "folder of the operators' <operator>.key files, instead of the configuration's [auth] key_dir");
  run_opt->excludes(check_opt);
  CLI11_PARSE(app, argc, argv);
  if (config_path.empty() && check_path.empty()) {
    std::fprintf(stderr, "hsad: give --config FILE or --check-config FILE (see --help)\n");
    return 2;
  }
  try {
    if (!check_path.empty()) {
      hsa::daemon::DaemonConfig config = hsa::daemon::load_config(check_path);
      if (!key_dir.empty()) config.auth.key_dir = key_dir;
      const std::vector<std::string> refused = hsa::daemon::check(config, lock_dir);
      for (const std::string& line : refused) std::fprintf(stderr, "%s\n", line.c_str());
      if (!refused.empty()) return 1;
      const std::string operators = hsa::daemon::operator_names(hsa::daemon::operator_keys(config.auth));
      std::printf("%s: OK\n%s", check_path.c_str(), hsa::daemon::describe(config).c_str());
      if (config.auth.require_auth) std::printf("  operator keys %s\n", operators.c_str());
      return 0;
    }
    if (!stats_json_path.empty()) {
      // Found out now, not after a run whose statistics could then not be written.
      std::ofstream probe(stats_json_path, std::ios::app);
      if (!probe) {
        std::fprintf(stderr, "hsad: cannot write --stats-json file '%s': %s\n", stats_json_path.c_str(),
                     std::strerror(errno));
        return 2;
      }
    }
    hsa::daemon::DaemonConfig config = hsa::daemon::load_config(config_path);
    if (!key_dir.empty()) config.auth.key_dir = key_dir;
    return hsa::daemon::run(config, duration_s, stats_json_path, lock_dir);
  } catch (const hsa::msgs::KeyFileError& e) {
    std::fprintf(stderr, "%s\n", hsa::daemon::key_refusal(config_path, e).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
