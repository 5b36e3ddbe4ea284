// hsactl: the operator's command line for hsad, over LCM.
//
//   hsactl [--axis NAME] [--key FILE] enable|disable|reset|acquire [--force]|release|mode position|open-loop|
//          open OPENING|move POS|step AMPL|sine AMPL FREQ|gains KP KI|status [--json]|drivers|watch|record FILE.csv|
//          log2csv LOG FILE.csv|excite [--at POS] [--amplitude MM] [--switching S] [--levels N|--prbs]
//          [--duration S] [--seed N] [--kp KP] [--record FILE.csv]
//   hsactl keygen NAME [--dir DIR]
//   hsactl captures [--dir DIR] | capture export FILE.mat FILE.csv [--force] |
//          scope FILE.mat [--signals A+B,C] [--out FILE.png]
//   hsactl capture [AXIS] [--pre S] [--post S] [--when SIGNAL --above|--below LEVEL [--single|--repeat]] |
//          capture [AXIS] --disarm |
//          scope --live AXIS (--now | --when SIGNAL --above|--below LEVEL) [--pre S] [--post S] [--timeout S]
//          [--dir DIR] [--signals A+B,C] [--out FILE.png]
//
// Setpoints and commands are signed with the operator's key (`--key FILE`, or the file named by
// HSA_KEY): hsad obeys only operators whose key it holds (msgs/README.md, Authentication). `keygen`
// makes a key, NAME.key with mode 0600, for the operator NAME; hsad's copy goes in its key_dir.
// `acquire` takes the axis's lease: until `release` (or the lease's timeout) only this operator
// commands it, except that anyone's DISABLE is obeyed. Each command waits for hsad's
// acknowledgement of its counter, sends it again if none comes, and prints hsad's reason if it
// refuses.
//
// `gains` sets the cylinder PI's kp (1/m) and ki (1/(m s)) while the axis runs (command_t.GAINS);
// the daemon refuses gains outside the axis's max_kp / max_ki, and hsactl then prints its reason.
//
// `mode` selects the axis's control mode (command_t.MODE): closed-loop position, or open loop, where
// the valve opening is commanded directly. `open` sends an opening with its duration in one MODE
// message (switching to open loop); hsad's RT loop commands opening 0 when the duration ends, so
// the valve holds it for that long however late this process or its messages are.
//
// `excite` makes a closed-loop identification run (command_t.EXCITE; Puglisi et al. 2015, section
// 3.1.1): hsad adds a PRMS (or PRBS) to the working point and follows it with P control of gain KP
// for the duration, then holds the working point with its PI gains back. hsad refuses a run that
// would leave the soft limits, the following-error or speed bound, or the gain margin it needs,
// with the reason. With --record the run's telemetry goes to the CSV `hsa-analyze identify` reads.
//
// hsactl believes only a status hsad signed for this operator (status_verifier.hpp), and signs its
// commands for the daemon that status came from. What failed verification is counted and named;
// without a verified answer hsactl exits 3 (also always without a key, when nothing can be verified).
//
// `captures`, `capture export` and `scope` read the flight recorder's files on this machine
// (docs/flight-recorder.md) and talk to no daemon: a file that is no capture is refused (exit 2).
// `capture AXIS` is a command to hsad (command_t.CAPTURE, signed and leased as every command): a
// capture now, or a condition on a capture file's signal armed (single-shot or repeated) or
// disarmed; hsad refuses lengths its ring cannot hold, with the reason. `scope --live AXIS` sends
// such a trigger, waits (at most --timeout s) for the capture file in the folder and draws it.
//
// Positions are given and shown in mm, pressures in bar; the wire carries SI units. Commands that
// change the axis wait for its status to confirm and exit non-zero (with the daemon's reason) when
// it does not, so scripts can rely on the exit code. Every wait is bounded.
#include <CLI/CLI.hpp>

#include <unistd.h>
#include <sys/ioctl.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "msgs/auth/operator_key.hpp"
#include "tools/hsactl/axis_commands.hpp"
#include "tools/hsactl/capture_command.hpp"
#include "tools/hsactl/capture_csv.hpp"
#include "tools/hsactl/capture_list.hpp"
#include "tools/hsactl/capture_scope.hpp"
#include "tools/hsactl/excite_command.hpp"
#include "tools/hsactl/gains_file.hpp"
#include "tools/hsactl/interrupt.hpp"
#include "tools/hsactl/lcm_session.hpp"
#include "tools/hsactl/observe_commands.hpp"
#include "tools/hsactl/suggest.hpp"

namespace {

void on_signal(int) { hsa::ctl::interrupted = true; }

// The word CLI11 found where a command belongs but knows no command by: the first it left over
// that is not an option. None when a command was given (its own errors are CLI11's to report).
std::optional<std::string> unknown_command_word(const CLI::App& app) {
  if (!app.get_subcommands().empty()) return std::nullopt;
  for (const std::string& word : app.remaining())
    if (!word.starts_with("-")) return word;
  return std::nullopt;
}

// CLI11 answers a mistyped command with "A subcommand is required"; hsactl names the word and the
// command probably meant. The words are CLI11's, so every option's value is skipped as it parses.
// Returns the exit code when hsactl is to stop here (an error, --help, --version).
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::RequiredError& e) {
    const std::optional<std::string> word = unknown_command_word(app);
    if (!word) return app.exit(e);
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
      names.push_back(sub->get_name());
    std::fprintf(stderr, "hsactl: %s (hsactl --help lists them)\n", hsa::ctl::unknown_command(*word, names).c_str());
    return 2;
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return std::nullopt;
}

}  // namespace

using namespace hsa::ctl;

int main(int argc, char** argv) {
  CLI::App app{"hsactl: operate an hsad axis over LCM (positions in mm, pressures in bar)"};
  app.set_version_flag("--version", "hsactl " HSA_VERSION);
  app.require_subcommand(1);
  std::string axis = "lift";
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  app.add_option("--axis", axis, "axis name (its LCM channels are HSA/<axis>/...)")->capture_default_str();
  app.add_option("--lcm-url", url, "LCM provider URL")->capture_default_str();
  std::string key_path;
  app.add_option("--key", key_path,
                 "the operator's key file (<operator>.key) that signs setpoints and commands and verifies hsad's status")
      ->envname("HSA_KEY");
  double stamp_window_s = 2.0;
  app.add_option("--stamp-window", stamp_window_s,
                 "how far a status's stamp may be from this host's clock, s (as hsad's [auth] stamp_window_s)")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 60.0));

  std::string key_name, key_dir = ".";
  auto* keygen = app.add_subcommand("keygen", "make a new operator key NAME.key (mode 0600) in DIR");
  keygen->add_option("NAME", key_name, "operator id: 1 to 32 of [A-Za-z0-9_.-]")->required();
  keygen->add_option("--dir", key_dir, "folder to write it to")->capture_default_str();

  auto* enable = app.add_subcommand("enable", "enable the axis (it holds where it is)");
  auto* disable = app.add_subcommand("disable", "disable the axis (valve to its safe state)");
  auto* reset = app.add_subcommand("reset", "clear latched faults whose cause is gone");
  bool force = false;
  auto* acquire = app.add_subcommand("acquire", "take the axis: only this operator commands it until released");
  acquire->add_flag("--force", force, "take it even from another operator (hsad logs it)");
  auto* release = app.add_subcommand("release", "give the axis back");
  std::string mode_arg;
  auto* mode = app.add_subcommand("mode", "select the control mode: closed-loop position or open-loop valve opening");
  mode->add_option("MODE", mode_arg, "position | open-loop")
      ->required()
      ->check(CLI::IsMember({"position", "open-loop"}));
  double opening = 0, open_s = 1;
  auto* open = app.add_subcommand("open", "open loop: command a valve opening for a while, then 0");
  open->add_option("OPENING", opening, "valve opening in [-1, 1]")->required()->check(CLI::Range(-1.0, 1.0));
  // command_t.opening_duration_s's range: hsad refuses a longer one, hsactl says why before sending.
  open->add_option("--duration", open_s, "s, at most 600; hsad ends the opening")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->check(CLI::Range(0.0, 600.0));
  double position_mm = 0, amplitude_mm = 0, frequency_hz = 0, duration_s = 10, tolerance_mm = 0.1, timeout_s = 10;
  auto* move = app.add_subcommand("move", "move to a position and wait until it is reached");
  move->add_option("POS", position_mm, "target position, mm")->required();
  auto* step = app.add_subcommand("step", "step by AMPL mm from the current position and wait");
  step->add_option("AMPL", amplitude_mm, "step, mm (negative: down)")->required();
  double speed_mm_s = 0, accel_mm_s2 = 0;
  bool stream = false;
  for (auto* cmd : {move, step}) {
    cmd->add_option("--tolerance", tolerance_mm, "reached when within this, mm")->capture_default_str();
    cmd->add_option("--timeout", timeout_s, "give up after, s")->capture_default_str();
    // With a plant set hsad also bounds both by what the plant follows in the move's direction.
    cmd->add_option("--speed", speed_mm_s,
                    "cruise speed, mm/s (default: the axis's max_speed_m_s; with a plant set, at most the "
                    "plant's speed limit in the move's direction)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--accel", accel_mm_s2,
                    "acceleration, mm/s^2 (default and bound: the axis's max_accel_m_s2; with a plant set, at "
                    "most the plant's limit in the move's direction)")
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--stream", stream, "stream setpoints at 100 Hz instead of letting hsad generate the move");
  }
  auto* sine_cmd = app.add_subcommand("sine", "track a sine around the current position");
  sine_cmd->add_option("AMPL", amplitude_mm, "amplitude, mm")->required()->check(CLI::PositiveNumber);
  sine_cmd->add_option("FREQ", frequency_hz, "frequency, Hz")->required()->check(CLI::PositiveNumber);
  sine_cmd->add_option("--duration", duration_s, "s")->capture_default_str();
  double kp = 0, ki = 0;
  auto* gains_cmd =
      app.add_subcommand("gains", "print the cylinder PI's gains, or set them (within the axis's max_kp, max_ki)");
  auto* kp_arg = gains_cmd->add_option("KP", kp, "proportional gain, 1/m");
  gains_cmd->add_option("KI", ki, "integral gain, 1/(m s)")->needs(kp_arg);
  kp_arg->needs(gains_cmd->get_option("KI"));
  std::string gains_file;
  auto* from_arg = gains_cmd->add_option("--from", gains_file, "send the kp and ki of this file (hsa-analyze tune --out)")
                       ->check(CLI::ExistingFile)
                       ->excludes(kp_arg);
  bool json = false;
  auto* status_cmd = app.add_subcommand("status", "print the axis status");
  status_cmd->add_flag("--json", json, "as one JSON object");
  auto* drivers_cmd = app.add_subcommand("drivers", "each driver of the axis: state, link, error counts, last error");
  auto* axes_cmd = app.add_subcommand("axes", "the axes that answer, with their state");
  auto* watch_cmd = app.add_subcommand("watch", "live view of the axis");
  double watch_s = 1e9;
  watch_cmd->add_option("--duration", watch_s, "stop after, s (default: until Ctrl-C)");
  std::string csv, log_path;
  auto* record_cmd = app.add_subcommand("record", "write telemetry to CSV");
  record_cmd->add_option("FILE", csv, "CSV file")->required();
  record_cmd->add_option("--duration", duration_s, "s")->capture_default_str();
  auto* log2csv = app.add_subcommand("log2csv", "turn an lcm-logger log into telemetry CSV");
  log2csv->add_option("LOG", log_path, "LCM log file")->required()->check(CLI::ExistingFile);
  log2csv->add_option("FILE", csv, "CSV file")->required();
  ExciteOptions excitation;
  double excite_at_mm = 0, excite_amplitude_mm = 1.0;
  auto* excite_cmd = app.add_subcommand(
      "excite", "identification run: PRMS/PRBS around a working point under P control, timed by hsad");
  auto* excite_at = excite_cmd->add_option("--at", excite_at_mm, "working point, mm (default: where the rod is)");
  excite_cmd->add_option("--amplitude", excite_amplitude_mm, "largest offset from the working point, mm")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  excite_cmd->add_option("--switching", excitation.switching_s, "time between level changes, s")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  auto* excite_levels = excite_cmd->add_option("--levels", excitation.levels, "PRMS levels over +-amplitude")
                            ->capture_default_str()
                            ->check(CLI::Range(2, 1000));
  excite_cmd->add_flag("--prbs", excitation.prbs, "a binary sequence (+-amplitude) instead of the PRMS")
      ->excludes(excite_levels);
  excite_cmd->add_option("--duration", excitation.duration_s, "s, at most 600; hsad ends the run")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->check(CLI::Range(0.0, 600.0));
  excite_cmd->add_option("--seed", excitation.seed, "the sequence's seed (the same seed, the same run)")
      ->capture_default_str();
  excite_cmd->add_option("--kp", excitation.kp_per_m, "P gain, valve opening per metre of error (200 = 0.2 per mm)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  excite_cmd->add_option("--record", excitation.record_path, "write the run's telemetry to this CSV (as record)");
  std::string captures_dir = default_capture_folder();
  auto* captures_cmd = app.add_subcommand("captures", "list the flight recorder's captures, newest first");
  captures_cmd->add_option("--dir", captures_dir, "the capture folder (default: $STATE_DIRECTORY, else /var/lib/hsa)")
      ->capture_default_str();
  std::string capture_mat, capture_csv, scope_signals = kDefaultScopeSignals, scope_out;
  bool capture_force = false;
  auto* capture_cmd = app.add_subcommand(
      "capture", "take a capture of AXIS now, arm or disarm a condition trigger; or export a capture file");
  capture_cmd->require_subcommand(0, 1);
  std::string capture_axis;
  capture_cmd->add_option("AXIS", capture_axis, "the axis (default: --axis)");
  CaptureOptions capture_opts;
  double live_timeout_s = 30.0;
  bool capture_single = false, live_now = false;
  std::string live_axis;
  auto* scope_cmd = app.add_subcommand("scope", "draw a capture around its trigger (gnuplot): to a PNG, or the terminal; "
                                                "--live: trigger one and draw it");
  // The trigger options, the same for `capture` and `scope --live`.
  for (auto* cmd : {capture_cmd, scope_cmd}) {
    cmd->add_option("--pre", capture_opts.pre_s, "s of history before the trigger (default: what the ring holds)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--post", capture_opts.post_s, "s after the trigger (default: [axes.recorder] post_trigger_s)")
        ->check(CLI::NonNegativeNumber);
    auto* when = cmd->add_option("--when", capture_opts.signal,
                                 "arm a condition on this signal of the capture file (e.g. following_error_m)");
    cmd->add_option("--above", capture_opts.above, "fire when the signal rises above this level (its unit)")
        ->needs(when);
    cmd->add_option("--below", capture_opts.below, "fire when the signal falls below this level (its unit)")
        ->needs(when);
    if (cmd == capture_cmd) {
      auto* single = cmd->add_flag("--single", capture_single, "fire once, then disarm (the default)")->needs(when);
      cmd->add_flag("--repeat", capture_opts.repeat, "fire at every crossing")->needs(when)->excludes(single);
      cmd->add_flag("--disarm", capture_opts.disarm, "disarm the axis's condition")->excludes(when);
    }
  }
  auto* export_cmd = capture_cmd->add_subcommand("export", "write a capture as CSV: a column per signal, and trigger");
  export_cmd->add_option("FILE.mat", capture_mat, "capture file")->required();
  export_cmd->add_option("FILE.csv", capture_csv, "CSV file to write")->required();
  export_cmd->add_flag("--force", capture_force, "overwrite FILE.csv if it exists");
  auto* scope_file = scope_cmd->add_option("FILE.mat", capture_mat, "capture file");
  auto* live_opt = scope_cmd->add_option("--live", live_axis,
                                         "arm a trigger on this axis (--when ..., or --now), wait for its capture, draw it")
                       ->excludes(scope_file);
  scope_cmd->add_flag("--now", live_now, "with --live: a capture now")->needs(live_opt)->excludes("--when");
  scope_cmd->add_option("--timeout", live_timeout_s, "with --live: give up after, s")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->needs(live_opt);
  scope_cmd->add_option("--dir", captures_dir, "with --live: the capture folder (default: as captures)")
      ->needs(live_opt);
  auto* signals_opt = scope_cmd->add_option("--signals", scope_signals,
                                            "panels, comma-separated; signals joined by + share one")
                          ->capture_default_str();
  scope_cmd->add_option("--out", scope_out,
                        "PNG to write (default: the terminal when stdout is one, else FILE.png in this folder)");
  if (const std::optional<int> code = parse_command_line(app, argc, argv)) return *code;
  if (excite_at->count() > 0) excitation.working_point_m = excite_at_mm * 1e-3;
  excitation.amplitude_m = excite_amplitude_mm * 1e-3;

  // scope: draws `mat`; the exit code.
  const auto draw = [&](const std::string& mat) -> int {
    ScopeTarget target;
    target.png = scope_out;
    // Not a terminal (a pipe, a script): a PNG in the current folder rather than text art.
    if (target.png.empty() && isatty(STDOUT_FILENO) == 0)
      target.png = std::filesystem::path(mat).stem().string() + ".png";
    winsize size{};
    if (target.png.empty() && ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 20 && size.ws_row > 10) {
      target.columns = size.ws_col;
      target.lines = size.ws_row - 1;
    }
    draw_scope(mat, scope_signals, signals_opt->count() == 0, target);
    if (!target.png.empty()) std::printf("%s\n", target.png.c_str());
    return 0;
  };
  // captures, capture export, scope FILE.mat: the exit code.
  const auto capture_command = [&]() -> int {
    if (*captures_cmd) {
      print_capture_list(stdout, captures_dir, list_captures(captures_dir));
      return 0;
    }
    if (*export_cmd) {
      export_capture_csv(capture_mat, capture_csv, capture_force);
      return 0;
    }
    return draw(capture_mat);
  };
  // capture AXIS and scope --live talk to hsad: checked before anything is sent.
  const bool capture_trigger = *capture_cmd && !*export_cmd;
  const bool live = *scope_cmd && live_opt->count() > 0;
  if (*scope_cmd) {
    if (const std::string why = scope_command_line_error(live, scope_file->count() > 0, live_now, capture_opts);
        !why.empty()) {
      std::fprintf(stderr, "hsactl: %s\n", why.c_str());
      return 2;
    }
  }
  if (capture_trigger || live) {
    if (const std::string why = capture_options_error(capture_opts); !why.empty()) {
      std::fprintf(stderr, "hsactl: %s: %s\n", live ? "scope --live" : "capture", why.c_str());
      return 2;
    }
    if (capture_trigger && !capture_axis.empty()) axis = capture_axis;
    if (live) axis = live_axis;
  }

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    if (*log2csv) return log_to_csv(log_path, axis, csv);
    if (*captures_cmd || (*capture_cmd && !capture_trigger) || (*scope_cmd && !live)) {
      // Files on this machine, no daemon: every failure names the file, exit 2.
      try {
        return capture_command();
      } catch (const std::exception& e) {
        std::fprintf(stderr, "hsactl: %s\n", e.what());
        return 2;
      }
    }
    if (from_arg->count() > 0) {  // a bad file is refused before anything is sent
      const hsa::ctl::GainsFromFile g = hsa::ctl::read_gains_file(gains_file);
      kp = g.kp;
      ki = g.ki;
    }
    if (*keygen) {
      std::printf("%s\n", hsa::msgs::write_new_key(key_dir, key_name).c_str());
      return 0;
    }
    // The command on the axis: its exit code.
    const auto run_axis_command = [&](LcmSession& session) -> int {
      const bool set_gains = *gains_cmd && (kp_arg->count() > 0 || from_arg->count() > 0);
      const bool sends = *enable || *disable || *reset || *mode || *open || *move || *step || *sine_cmd ||
                         set_gains || *acquire || *release || *excite_cmd || capture_trigger || live;
      if (sends) {
        // Unsigned messages to a daemon that requires signatures would only be counted and dropped;
        // signed ones go to the daemon whose status hsactl verified, and to no other.
        if (!first_status(session, app.get_subcommands().front()->get_name().c_str())) {
          return no_answer_code(session, 2);
        }
        if (session.status()->auth_required && !session.signing()) {
          std::fprintf(stderr, "hsactl: axis '%s' obeys signed commands only: give --key FILE (or set HSA_KEY)\n",
                       axis.c_str());
          return 1;
        }
        // Another operator's lease refuses everything but DISABLE and a forced ACQUIRE: say so now.
        const std::string& holder = session.status()->lease_holder;
        if (!holder.empty() && holder != session.operator_id() && !*disable && !(*acquire && force)) {
          std::fprintf(stderr, "hsactl: axis '%s' is held by operator '%s' (hsactl acquire --force takes it over)%s\n",
                       axis.c_str(), holder.c_str(), session.unverified_tag());
          return 1;
        }
      }
      if (*enable) return command_and_confirm(session, hsa::command_t::ENABLE, hsa::status_t::STATE_ENABLED, "enable");
      if (*disable)
        return command_and_confirm(session, hsa::command_t::DISABLE, hsa::status_t::STATE_DISABLED, "disable");
      if (*reset) return command_and_confirm(session, hsa::command_t::RESET, hsa::status_t::STATE_DISABLED, "reset");
      if (*acquire) return lease_command(session, true, force);
      if (*release) return lease_command(session, false, false);
      if (*mode)
        return mode_and_confirm(session, mode_arg == "position" ? hsa::command_t::MODE_POSITION
                                                                : hsa::command_t::MODE_VALVE_OPENING);
      if (capture_trigger) return request_capture(session, capture_opts);
      if (live) return live_scope(session, capture_opts, captures_dir, live_timeout_s, draw);
      if (*status_cmd) return status(session, json);
      if (*drivers_cmd) return drivers(session);
      if (*axes_cmd) return axes(session);
      if (*gains_cmd) return set_gains ? gains_and_confirm(session, kp, ki) : print_gains(session);
      if (*watch_cmd) return watch(session, watch_s);
      if (*record_cmd) return record(session, csv, duration_s);
      if (!wait_for_telemetry(session)) return no_answer_code(session, 2);
      if (*open) return open_valve(session, opening, open_s);
      if (*excite_cmd) return excite(session, excitation);
      const MoveOptions how{.speed_m_s = speed_mm_s * 1e-3,
                            .accel_m_s2 = accel_mm_s2 * 1e-3,
                            .tolerance_m = tolerance_mm * 1e-3,
                            .timeout_s = timeout_s,
                            .stream = stream};
      if (*move) return move_to(session, position_mm * 1e-3, how);
      // From where hsad says the rod is (telemetry is not authenticated).
      if (*step) return move_to(session, session.status()->position_m + amplitude_mm * 1e-3, how);
      if (*sine_cmd) return sine(session, amplitude_mm * 1e-3, frequency_hz, duration_s);
      return 0;
    };
    std::optional<hsa::msgs::OperatorKey> key;
    if (!key_path.empty()) key = hsa::msgs::read_key_file(key_path);
    LcmSession session(url, axis, std::move(key), stamp_window_s);
    const int code = run_axis_command(session);
    // Without a key hsactl cannot tell hsad's answer from a forgery: what it printed is marked so,
    // and a command is not reported as a success (watch and record show telemetry, never verified).
    if (code == 0 && !session.can_verify() && !*watch_cmd && !*record_cmd) return kExitUnverified;
    return code;
  } catch (const hsa::msgs::KeyFileError& e) {
    std::fprintf(stderr, "hsactl: key: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
