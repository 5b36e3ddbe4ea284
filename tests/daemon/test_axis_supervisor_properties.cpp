// The axis supervisor's rules (daemon/supervisor/axis_supervisor.hpp) checked on random sequences
// of events instead of chosen examples: input staleness, out-of-range, non-finite and jumping
// samples, driver errors and their recovery, e-stop edges, late cycles, streamed setpoints, every
// command of HSA_COMMAND_KINDS with valid and invalid arguments, and non-finite loop outputs.
// After every cycle four properties must hold:
//
//   safe valve      the loops drive (valve enable on) only while ENABLED with no latched fault,
//                   and never in a cycle in which a condition that trips is present;
//   latched cause   a latched fault's record changes only through a successful reset;
//   one answer      every new command gets exactly one answer, accepted or refused with a reason
//                   the rules give for the state it was handled in;
//   no side effect  a refused command (and gains, which are the operator thread's) changes
//                   nothing: the same supervisor without it decides the same, now and next cycle.
//
// Which conditions are present, and which answer a command gets, is the test's own reading of the
// rules (Model, expected_refusal), from the inputs it generated, never the supervisor's code. The
// supervisor serves only as its own counterfactual: a copy of it runs each cycle without the
// command, which tells the state the command was handled in and what a refusal must leave as is.
//
// Leases are the LCM bridge's (daemon/lcm_bridge/command_lease.hpp): ACQUIRE and RELEASE never
// reach the supervisor, and a command refused for the lease never reaches it either. What a lease
// change leaves for the supervisor is commands from another operator: the generator gives each
// command a random ticket, and commands arrive in every state.
//
// CI runs kSequences sequences of up to kMaxEvents events from a fixed seed (kDefaultRcParams):
// 1000 sequences, 0.6 s of CPU in the RelWithDebInfo build (1.8 s on a loaded 2-core machine).
// RC_PARAMS in the environment replaces those settings, e.g. to reproduce a failure with the
// `reproduce` string it prints (tests/README.md).
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

#include "daemon/supervisor/axis_supervisor.hpp"
#include "tests/daemon/supervisor_test_params.hpp"

namespace hsa::daemon {

// So that a failed RC_ASSERT shows the states and reasons it compared (found by ADL, hence here).
template <typename E>
  requires std::is_same_v<E, AxisState> || std::is_same_v<E, ControlMode> || std::is_same_v<E, Refusal> ||
           std::is_same_v<E, FaultReason> || std::is_same_v<E, CommandKind>
static std::ostream& operator<<(std::ostream& os, E value) {
  return os << to_string(value);
}

namespace {

using io::SampleStatus;
using std::chrono::nanoseconds;

constexpr int kSequences = 1000;
constexpr int kMaxEvents = 300;
constexpr std::uint64_t kSeed = 20260101;
// Set before gtest's main and rapidcheck's first look at its configuration; setenv does not
// overwrite, so RC_PARAMS from the environment wins.
[[maybe_unused]] const bool kDefaultRcParams = [] {
  const std::string params = "seed=" + std::to_string(kSeed) + " max_success=" + std::to_string(kSequences);
  return ::setenv("RC_PARAMS", params.c_str(), 0) == 0;
}();

constexpr std::int64_t kPeriod = test::kSupervisorPeriodNs;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A finite speed bound, so that a move's speed can be over it and a jump is judged by time.
SupervisorParams property_params() {
  SupervisorParams p = test::short_supervisor_params();
  p.max_speed_m_s = 0.5;
  p.startup_timeout_ns = 200 * kPeriod;
  return p;
}
const SupervisorParams kParams = property_params();

// The bound inputs, in FaultSignal order (signal − 1).
constexpr int kPosition = 0, kPressureA = 1, kPressureB = 2, kSpool = 3, kEstop = 4;
constexpr int kSignals = static_cast<int>(kFaultSignalCount);

enum class Ev : std::uint8_t {
  cycles,            // n plain cycles
  late_cycle,        // one cycle `gap` after the last
  rod_glide,         // the rod moves to x within its speed bound, a cycle per step
  rod_jump,          // the rod's reading jumps by x in one sample
  rod_value,         // the rod's reading becomes x (outside the soft limits, non-finite)
  pressure,          // pressure A (n = 0) or B (n = 1) reads x
  status,            // input n's samples get `status`
  freeze,            // input n's timestamp stops (on) or advances again
  driver_error,      // the executive reports a driver error (on) or its recovery
  overruns,          // the executive's overrun streak is n
  estop,             // the e-stop is pressed (on) or released
  following_error,   // the loops' following error is x
  saturated,         // the loops' command is saturated (on)
  setpoint,          // a new streamed setpoint x with velocity y
  command,           // a new operator command `cmd`, in a cycle of its own or (on) in the next
                     // event's first, with whatever that changes
  output_not_finite, // the loops computed x (non-finite) in a cycle that drove
  recover,           // every input healthy again, then a reset and an enable, a cycle each
};

struct Event {
  Ev what = Ev::cycles;
  int n = 1;
  double x = 0.0;
  double y = 0.0;
  std::int64_t gap = kPeriod;
  bool on = false;
  SampleStatus status = SampleStatus::ok;
  AxisCommand cmd{};
};

std::ostream& operator<<(std::ostream& os, const Event& e) {
  switch (e.what) {
    case Ev::cycles: return os << "cycles(" << e.n << ")";
    case Ev::late_cycle: return os << "late_cycle(" << e.gap << " ns)";
    case Ev::rod_glide: return os << "rod_glide(" << e.x << " m)";
    case Ev::rod_jump: return os << "rod_jump(" << e.x << " m)";
    case Ev::rod_value: return os << "rod_value(" << e.x << " m)";
    case Ev::pressure: return os << "pressure(" << (e.n == 0 ? "A" : "B") << ", " << e.x << " Pa)";
    case Ev::status:
      return os << "status(" << to_string(static_cast<FaultSignal>(e.n + 1)) << ", " << io::to_string(e.status) << ")";
    case Ev::freeze: return os << "freeze(" << to_string(static_cast<FaultSignal>(e.n + 1)) << ", " << e.on << ")";
    case Ev::driver_error: return os << "driver_error(" << e.on << ")";
    case Ev::overruns: return os << "overruns(" << e.n << ")";
    case Ev::estop: return os << "estop(" << (e.on ? "pressed" : "released") << ")";
    case Ev::following_error: return os << "following_error(" << e.x << " m)";
    case Ev::saturated: return os << "saturated(" << e.on << ")";
    case Ev::setpoint: return os << "setpoint(" << e.x << ", " << e.y << " m/s)";
    case Ev::output_not_finite: return os << "output_not_finite(" << e.x << ")";
    case Ev::recover: return os << "recover";
    case Ev::command: break;
  }
  const AxisCommand& c = e.cmd;
  os << (e.on ? "command_with_next(" : "command(") << to_string(c.kind) << ", ticket " << c.ticket;
  switch (c.kind) {
    case CommandKind::set_mode:
      os << ", " << to_string(c.mode);
      if (c.has_opening) os << ", opening " << c.opening;
      break;
    case CommandKind::move_to:
      os << ", to " << c.move.target_m << " at " << c.move.speed_m_s << " m/s, " << c.move.accel_m_s2 << " m/s²";
      break;
    case CommandKind::gains: os << ", kp " << c.gains.kp << ", ki " << c.gains.ki; break;
    default: break;
  }
  return os << ")";
}

// ---- generators: the events the rules talk about, with values on both sides of each bound ----

template <typename T>
rc::Gen<T> one_of_values(std::vector<T> values) {
  return rc::gen::elementOf(std::move(values));
}

// A length in metres between lo and hi, in tenths of a millimetre.
rc::Gen<double> metres(double lo, double hi) {
  return rc::gen::map(rc::gen::inRange<int>(static_cast<int>(lo * 1e4), static_cast<int>(hi * 1e4) + 1),
                      [](int tenths_mm) { return tenths_mm * 1e-4; });
}

// Every kind of the command table, so a new kind is generated (and must be answered) at once.
constexpr CommandKind kCommandKinds[] = {
#define HSA_PROPERTY_KIND(kind, name) CommandKind::kind,
    HSA_COMMAND_KINDS(HSA_PROPERTY_KIND)
#undef HSA_PROPERTY_KIND
};

rc::Gen<AxisCommand> command_gen() {
  const double low = kParams.soft_limit_low_m, high = kParams.soft_limit_high_m, vmax = kParams.max_speed_m_s;
  return rc::gen::apply(
      [](CommandKind kind, bool open_loop, bool has_opening, double opening, double target, double speed,
         double accel, double kp, double ki, std::uint64_t ticket) {
        AxisCommand c;
        c.kind = kind;
        c.ticket = ticket;
        // As validation leaves them: only the fields the kind names are set.
        if (kind == CommandKind::set_mode) {
          c.mode = open_loop ? ControlMode::open_loop : ControlMode::position;
          c.has_opening = open_loop && has_opening;
          c.opening = c.has_opening ? opening : 0.0;
        } else if (kind == CommandKind::move_to) {
          c.move = {target, speed, accel};
        } else if (kind == CommandKind::gains) {
          c.gains = {kp, ki};
        } else if (kind == CommandKind::excite) {
          // ±1 mm around the target, for the move's speed as a duration (0, negative, NaN: invalid).
          c.excite = {.working_point_m = target, .amplitude_m = 1e-3, .switching_time_s = 0.01, .levels = 5,
                      .seed = ticket, .duration_s = speed, .kp_per_m = 200.0};
        }
        return c;
      },
      rc::gen::elementOf(std::vector<CommandKind>(std::begin(kCommandKinds), std::end(kCommandKinds))),
      rc::gen::arbitrary<bool>(), rc::gen::arbitrary<bool>(),
      rc::gen::oneOf(one_of_values<double>({-1.0, 0.0, 1.0}), rc::gen::map(rc::gen::inRange(-100, 101), [](int v) { return v / 100.0; })),
      rc::gen::oneOf(metres(low, high), one_of_values<double>({low, high, low - 1e-4, high + 1e-4, -0.1, kNaN, kInf})),
      one_of_values<double>({0.0, 0.05, vmax, vmax * 1.01, 2 * vmax, -0.1, kInf, kNaN}),
      one_of_values<double>({0.0, 0.5, 10.0, -1.0}),
      one_of_values<double>({0.0, 50.0, -5.0, kNaN}), one_of_values<double>({0.0, 10.0, -1.0, kInf}),
      rc::gen::inRange<std::uint64_t>(0, 4));
}

rc::Gen<int> signal_gen() { return rc::gen::inRange(0, kSignals); }

rc::Gen<Event> event_gen() {
  using rc::gen::map;
  const double low = kParams.soft_limit_low_m, high = kParams.soft_limit_high_m;
  const double pmax = kParams.pressure_max_pa, femax = kParams.following_error_max_m;
  const std::int64_t blind = kParams.max_blind_time_ns;
  const auto ev = [](Ev what) { Event e; e.what = what; return e; };
  return rc::gen::weightedOneOf<Event>({
      {8, map(rc::gen::inRange(1, 30), [=](int n) { Event e = ev(Ev::cycles); e.n = n; return e; })},
      {2, map(one_of_values<std::int64_t>({2 * kPeriod, blind / 2, blind, blind + 1, 3 * blind, 100'000'000}),
              [=](std::int64_t g) { Event e = ev(Ev::late_cycle); e.gap = g; return e; })},
      {4, map(metres(0.0, 0.31), [=](double x) { Event e = ev(Ev::rod_glide); e.x = x; return e; })},
      {1, map(rc::gen::oneOf(metres(0.02, 0.1), metres(-0.1, -0.02)),
              [=](double x) { Event e = ev(Ev::rod_jump); e.x = x; return e; })},
      {1, map(one_of_values<double>({low - 0.001, high + 0.001, low, high, kNaN, kInf}),
              [=](double x) { Event e = ev(Ev::rod_value); e.x = x; return e; })},
      {2, rc::gen::apply([=](int which, double x) { Event e = ev(Ev::pressure); e.n = which; e.x = x; return e; },
                         rc::gen::inRange(0, 2), one_of_values<double>({9e5, 12e5, pmax, pmax + 1e5, kNaN}))},
      {3, rc::gen::apply([=](int which, SampleStatus s) { Event e = ev(Ev::status); e.n = which; e.status = s; return e; },
                         signal_gen(),
                         one_of_values<SampleStatus>({SampleStatus::ok, SampleStatus::ok, SampleStatus::ok, SampleStatus::stale,
                                                      SampleStatus::out_of_range, SampleStatus::disconnected}))},
      {2, rc::gen::apply([=](int which, bool on) { Event e = ev(Ev::freeze); e.n = which; e.on = on; return e; },
                         signal_gen(), rc::gen::arbitrary<bool>())},
      {2, map(rc::gen::arbitrary<bool>(), [=](bool on) { Event e = ev(Ev::driver_error); e.on = on; return e; })},
      {1, map(rc::gen::inRange(0, 7), [=](int n) { Event e = ev(Ev::overruns); e.n = n; return e; })},
      {2, map(rc::gen::arbitrary<bool>(), [=](bool on) { Event e = ev(Ev::estop); e.on = on; return e; })},
      {1, map(one_of_values<double>({0.0, femax / 2, -2 * femax, kNaN}),
              [=](double x) { Event e = ev(Ev::following_error); e.x = x; return e; })},
      {1, map(rc::gen::arbitrary<bool>(), [=](bool on) { Event e = ev(Ev::saturated); e.on = on; return e; })},
      {4, rc::gen::apply([=](double x, double v) { Event e = ev(Ev::setpoint); e.x = x; e.y = v; return e; },
                         rc::gen::oneOf(metres(0.0, 0.31), one_of_values<double>({-0.5, 0.5, kNaN})),
                         one_of_values<double>({0.0, 0.1, -0.1}))},
      {10, rc::gen::apply([=](AxisCommand c, bool with_next) { Event e = ev(Ev::command); e.cmd = c; e.on = with_next; return e; },
                          command_gen(), rc::gen::arbitrary<bool>())},
      {1, map(one_of_values<double>({kNaN, kInf, -kInf}),
              [=](double x) { Event e = ev(Ev::output_not_finite); e.x = x; return e; })},
      // Without it most sequences would end their first fault in FAULT or ESTOP for good.
      {4, rc::gen::just(ev(Ev::recover))},
  });
}

// ---- the model: which conditions the rules say are present, from the inputs alone ----

bool usable(const io::AnalogSample& s) { return s.ok() && std::isfinite(s.value); }
bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
bool same(const FaultRecord& a, const FaultRecord& b) {
  return a.reason == b.reason && a.signal == b.signal && a.status == b.status && same(a.value, b.value) &&
         same(a.limit, b.limit) && a.t_ns == b.t_ns;
}
bool same(const Decision& a, const Decision& b) {
  return a.state == b.state && a.mode == b.mode && a.drive == b.drive && a.activate == b.activate &&
         a.holding == b.holding && same(a.rod_setpoint_m, b.rod_setpoint_m) &&
         same(a.velocity_ff_m_s, b.velocity_ff_m_s) && same(a.opening, b.opening) && a.tripped == b.tripped;
}

constexpr std::uint32_t bit(FaultReason r) { return fault_bit(r); }
const std::uint32_t kPersistent = fault_mask(fault_kind::persistent);

// The lowest (highest-priority) reason of a mask.
FaultReason first_of(std::uint32_t mask) {
  for (std::size_t r = 1; r < kFaultReasonCount; ++r) {
    if (mask & (1u << r)) return static_cast<FaultReason>(r);
  }
  return FaultReason::none;
}

// What the header's rules say about the inputs of one cycle: the conditions certainly present
// (those whose rule depends on the inputs and the time alone; the loops' streaks and the soft
// limits also depend on the state, and are left to the other properties).
class Model {
 public:
  // Call once per cycle, before the supervisor's update, with the state it starts the cycle in.
  std::uint32_t present(const SupervisorInputs& in, AxisState state_before) {
    std::uint32_t p = 0;
    if (in.cycle_gap_ns > kParams.max_blind_time_ns) p |= bit(FaultReason::blind_time);
    if (!in.estop.ok() || in.estop.value) p |= bit(FaultReason::estop);  // unreadable counts as pressed
    if (in.executive.driver_error) p |= bit(FaultReason::driver_error);
    if (in.executive.overrun_streak >= kParams.overrun_streak_max) p |= bit(FaultReason::rt_overruns);
    for (const io::AnalogSample* s : {&in.position, &in.pressure_a, &in.pressure_b, &in.spool}) {
      if (!usable(*s)) p |= bit(FaultReason::sensor_not_ok);
    }
    for (const io::AnalogSample* s : {&in.pressure_a, &in.pressure_b}) {
      if (usable(*s) && s->value > kParams.pressure_max_pa) p |= bit(FaultReason::over_pressure);
    }
    // Age: a timestamp unchanged for longer than input_stale_ns while its sample is ok and its
    // driver reads (a dropout or a driver error restarts the clock).
    const std::int64_t stamps[kSignals] = {in.position.timestamp.count(), in.pressure_a.timestamp.count(),
                                           in.pressure_b.timestamp.count(), in.spool.timestamp.count(),
                                           in.estop.timestamp.count()};
    const bool oks[kSignals] = {in.position.ok(), in.pressure_a.ok(), in.pressure_b.ok(), in.spool.ok(), in.estop.ok()};
    for (int i = 0; i < kSignals; ++i) {
      Age& a = ages_[i];
      if (!oks[i] || in.executive.driver_error) {
        a.seen = false;
      } else if (!a.seen || a.stamp != stamps[i]) {
        a = {stamps[i], in.t_ns, true};
      } else if (in.t_ns - a.since > kParams.input_stale_ns) {
        p |= bit(i == kEstop ? FaultReason::estop : FaultReason::sensor_not_ok);
      }
    }
    // The encoder: stale after encoder_stale_cycles usable samples with one timestamp, and a jump
    // judged against the time between two usable samples in a row.
    if (usable(in.position)) {
      const std::int64_t stamp = in.position.timestamp.count();
      const bool fresh = !have_stamp_ || stamp != last_stamp_;
      same_stamp_cycles_ = fresh ? 0 : same_stamp_cycles_ + 1;
      if (same_stamp_cycles_ >= kParams.encoder_stale_cycles) p |= bit(FaultReason::encoder_stale);
      if (fresh && have_position_) {
        const double dt = static_cast<double>(stamp - last_stamp_) * 1e-9;
        if (std::abs(in.position.value - last_position_) > kParams.max_speed_m_s * dt + kParams.encoder_jump_max_m) {
          p |= bit(FaultReason::encoder_jump);
        }
      }
      last_stamp_ = stamp;
      have_stamp_ = true;
      last_position_ = in.position.value;
      have_position_ = true;
    } else {
      have_position_ = false;
      same_stamp_cycles_ = 0;
    }
    // INIT waits for every input's first sample and meanwhile judges only what needs no input and
    // an e-stop that reads asserted.
    starting_ = state_before == AxisState::init &&
                (in.position.status == SampleStatus::disconnected || in.pressure_a.status == SampleStatus::disconnected ||
                 in.pressure_b.status == SampleStatus::disconnected || in.spool.status == SampleStatus::disconnected ||
                 in.estop.status == SampleStatus::disconnected);
    if (starting_) {
      const bool pressed = in.estop.ok() && in.estop.value;
      p &= fault_mask(fault_kind::while_starting) | (pressed ? bit(FaultReason::estop) : 0u);
    }
    return p;
  }
  [[nodiscard]] bool starting() const { return starting_; }

 private:
  struct Age {
    std::int64_t stamp = 0;
    std::int64_t since = 0;
    bool seen = false;
  };
  Age ages_[kSignals]{};
  bool have_stamp_ = false;
  std::int64_t last_stamp_ = 0;
  std::uint32_t same_stamp_cycles_ = 0;
  bool have_position_ = false;
  double last_position_ = 0.0;
  bool starting_ = false;
};

// The answer the rules give to a command handled in `state` and `mode` (after this cycle's faults).
// A reset's depends on the conditions present too, and is judged apart (Rig::check_reset).
Refusal expected_refusal(const AxisCommand& c, AxisState state, ControlMode mode) {
  switch (c.kind) {
    case CommandKind::enable:
      if (state == AxisState::init) return Refusal::starting;
      if (state == AxisState::fault) return Refusal::reset_first;
      if (state == AxisState::estop) return Refusal::estop_active;
      return Refusal::none;
    case CommandKind::move_to: {
      if (state != AxisState::enabled) return Refusal::not_enabled;
      if (mode != ControlMode::position) return Refusal::not_position_mode;
      const MoveRequest& m = c.move;
      if (!(m.target_m >= kParams.soft_limit_low_m && m.target_m <= kParams.soft_limit_high_m)) {
        return Refusal::target_outside_limits;
      }
      const double speed = m.speed_m_s > 0.0 ? m.speed_m_s : kParams.max_speed_m_s;
      if (!(speed <= kParams.max_speed_m_s)) return Refusal::speed_over_limit;
      // Unconfigured, the acceleration bound is the axis's speed reached in kDefaultRampS.
      if (m.accel_m_s2 > kParams.max_speed_m_s / safety_defaults::kDefaultRampS) return Refusal::accel_over_limit;
      return Refusal::none;
    }
    case CommandKind::excite: {
      if (state != AxisState::enabled) return Refusal::not_enabled;
      if (mode != ControlMode::position) return Refusal::not_position_mode;
      const ExcitationRequest& e = c.excite;
      if (!(e.working_point_m - e.amplitude_m >= kParams.soft_limit_low_m &&
            e.working_point_m + e.amplitude_m <= kParams.soft_limit_high_m)) {
        return Refusal::excitation_outside_limits;
      }
      if (!(e.duration_s > 0.0 && e.duration_s <= kMaxExcitationDurationS)) return Refusal::excitation_invalid;
      return Refusal::none;
    }
    default:
      return Refusal::none;  // disable, set_mode, gains: always accepted; reset: judged apart
  }
}

// The rig: the inputs the axis loop would hand the supervisor, changed by events, and the checks.
class Rig {
 public:
  Rig() {
    in_.position = {0.150, {}, SampleStatus::ok};
    in_.pressure_a = {12e5, {}, SampleStatus::ok};
    in_.pressure_b = {9e5, {}, SampleStatus::ok};
    in_.spool = {0.0, {}, SampleStatus::ok};
    in_.estop = {false, {}, SampleStatus::ok};
    in_.has_spool = true;
    in_.has_estop = true;
  }

  void apply(const Event& e) {
    switch (e.what) {
      case Ev::cycles:
        for (int i = 0; i < e.n; ++i) cycle();
        return;
      case Ev::late_cycle: return cycle(e.gap);
      case Ev::rod_glide: {
        // 4 mm a cycle: under the jump margin, so the move itself never trips.
        const double x = e.x;
        for (int i = 0; i < 100 && std::abs(rod() - x) > 0.004; ++i) {
          in_.position.value = rod() + (rod() < x ? 0.004 : -0.004);
          cycle();
        }
        in_.position.value = x;
        return cycle();
      }
      case Ev::rod_jump:
        in_.position.value = rod() + e.x;
        return cycle();
      case Ev::rod_value:
        in_.position.value = e.x;
        return cycle();
      case Ev::pressure:
        (e.n == 0 ? in_.pressure_a : in_.pressure_b).value = e.x;
        return cycle();
      case Ev::status:
        if (e.n == kEstop) {
          in_.estop.status = e.status;
        } else {
          analog(e.n).status = e.status;
        }
        return cycle();
      case Ev::freeze:
        frozen_[e.n] = e.on;
        return cycle();
      case Ev::driver_error:
        in_.executive.driver_error = e.on;
        return cycle();
      case Ev::overruns:
        in_.executive.overrun_streak = static_cast<std::uint32_t>(e.n);
        return cycle();
      case Ev::estop:
        in_.estop.value = e.on;
        return cycle();
      case Ev::following_error:
        in_.following_error_m = e.x;
        return cycle();
      case Ev::saturated:
        in_.command_saturated = e.on;
        return cycle();
      case Ev::setpoint:
        op_.setpoint.seq += 1;
        op_.setpoint.target = e.x;
        op_.setpoint.velocity_m_s = e.y;
        return cycle();
      case Ev::command:
        op_.command = e.cmd;
        op_.command.seq = ++command_seq_;
        if (!e.on) cycle();
        return;
      case Ev::output_not_finite:
        return output_not_finite(e.x);
      case Ev::recover:
        return recover();
    }
  }

 private:
  double rod() const { return std::isfinite(in_.position.value) ? in_.position.value : 0.150; }
  io::AnalogSample& analog(int which) {
    io::AnalogSample* samples[] = {&in_.position, &in_.pressure_a, &in_.pressure_b, &in_.spool};
    return *samples[which];
  }

  void recover() {
    healthy();
    cycle();
    for (const CommandKind kind : {CommandKind::reset, CommandKind::enable}) {
      op_.command = {};
      op_.command.kind = kind;
      op_.command.seq = ++command_seq_;
      cycle();
    }
  }
  void healthy() {
    for (int i = 0; i < kSignals; ++i) frozen_[i] = false;
    for (io::AnalogSample* s : {&in_.position, &in_.pressure_a, &in_.pressure_b, &in_.spool}) s->status = SampleStatus::ok;
    in_.position.value = std::isfinite(in_.position.value) ? std::clamp(in_.position.value, 0.01, 0.29) : 0.150;
    in_.pressure_a.value = 12e5;
    in_.pressure_b.value = 9e5;
    in_.estop = {false, in_.estop.timestamp, SampleStatus::ok};
    in_.executive = {};
    in_.following_error_m = 0.0;
    in_.command_saturated = false;
  }

  // One cycle `gap` after the last, then the properties.
  void cycle(std::int64_t gap = kPeriod) {
    t_ += gap;
    in_.t_ns = t_;
    in_.cycle_gap_ns = gap;
    for (int i = 0; i < kSignals; ++i) {
      if (frozen_[i]) continue;
      if (i == kEstop) {
        in_.estop.timestamp = nanoseconds(t_);
      } else {
        analog(i).timestamp = nanoseconds(t_);
      }
    }
    const AxisState state_before = sup_.state();
    const FaultRecord fault_before = sup_.fault();
    const CommandOutcome answer_before = sup_.last_command();
    const std::uint64_t refused_before = sup_.commands_refused();
    const std::uint32_t present = model_.present(in_, state_before);
    const bool new_command = op_.command.seq != handled_seq_;
    handled_seq_ = op_.command.seq;
    // The same supervisor, and the same cycle without the command: what it would have done.
    AxisSupervisor without = sup_;
    AxisInputsFromOperator op_without = op_;
    op_without.command = last_op_command_;

    const Decision d = sup_.update(in_, op_);
    const Decision d_without = without.update(in_, op_without);
    last_op_command_ = op_.command;
    last_drive_ = d.drive;
    seen_.drove |= d.drive;
    seen_.tripped_driving |= state_before == AxisState::enabled && d.tripped;
    seen_.estop |= sup_.state() == AxisState::estop;

    // safe valve
    RC_ASSERT(d.state == sup_.state());
    RC_ASSERT(d.drive == (sup_.state() == AxisState::enabled));
    if (d.drive) RC_ASSERT(sup_.fault().reason == FaultReason::none);
    if (!d.drive) RC_ASSERT(d.opening == 0.0 && d.rod_setpoint_m == 0.0 && !d.holding);
    // Every condition present trips from INIT, DISABLED and ENABLED (blind time only from
    // ENABLED), and the e-stop goes to ESTOP from any state but FAULT, whose latched cause it
    // leaves alone: none of them lets the loops drive.
    const std::uint32_t trips = state_before == AxisState::enabled ? present : present & ~bit(FaultReason::blind_time);
    if (trips != 0) RC_ASSERT(!d.drive);
    if (present & bit(FaultReason::estop)) {
      RC_ASSERT(sup_.state() == (state_before == AxisState::fault ? AxisState::fault : AxisState::estop));
    }

    const bool reset_accepted = new_command && op_.command.kind == CommandKind::reset && sup_.last_command().accepted;
    if (trips != 0 && !reset_accepted) {
      RC_ASSERT(sup_.state() == AxisState::fault || sup_.state() == AxisState::estop);
    }
    // latched cause
    const bool latched = sup_.state() == AxisState::fault || sup_.state() == AxisState::estop;
    RC_ASSERT(latched == (sup_.fault().reason != FaultReason::none));
    if (fault_before.reason != FaultReason::none && !same(fault_before, sup_.fault())) {
      RC_ASSERT(reset_accepted);
      RC_ASSERT(sup_.fault().reason == FaultReason::none);
    }

    // one answer
    const CommandOutcome& answer = sup_.last_command();
    if (!new_command) {
      RC_ASSERT(answer.seq == answer_before.seq && sup_.commands_refused() == refused_before);
      return;
    }
    const AxisCommand& c = op_.command;
    RC_ASSERT(answer.seq == c.seq);
    RC_ASSERT(answer.ticket == c.ticket);
    RC_ASSERT(answer.kind == c.kind);
    RC_ASSERT(answer.accepted == (answer.refusal == Refusal::none));
    seen_.refused |= !answer.accepted;
    RC_ASSERT(sup_.commands_refused() == refused_before + (answer.accepted ? 0 : 1));
    if (answer.refusal != Refusal::cause_present && answer.refusal != Refusal::estop_pressed) {
      RC_ASSERT(answer.blocking == FaultReason::none);
    }
    // The command was handled in the state the faults left: the state after, unless it moved it.
    if (c.kind == CommandKind::reset) {
      check_reset(answer, state_before, present);
    } else if (c.kind == CommandKind::enable && answer.accepted) {
      RC_ASSERT(sup_.state() == AxisState::enabled);
      RC_ASSERT(expected_refusal(c, without.state(), without.mode()) == Refusal::none);
    } else {
      RC_ASSERT(answer.refusal == expected_refusal(c, without.state(), without.mode()));
    }
    if (c.kind == CommandKind::disable) RC_ASSERT(sup_.state() != AxisState::enabled);
    if (c.kind == CommandKind::set_mode) RC_ASSERT(sup_.mode() == c.mode);

    // no side effect
    if (!answer.accepted || c.kind == CommandKind::gains) {
      unchanged(d, d_without, without);
      // Nothing hidden either: both decide the same in the cycle that follows.
      AxisSupervisor with = sup_;
      SupervisorInputs next = in_;
      next.t_ns += kPeriod;
      next.cycle_gap_ns = kPeriod;
      RC_ASSERT(same(with.update(next, op_), without.update(next, op_without)));
    }
  }

  void check_reset(const CommandOutcome& answer, AxisState state_before, std::uint32_t present) {
    const bool was_latched = state_before == AxisState::fault || state_before == AxisState::estop;
    switch (answer.refusal) {
      case Refusal::none:
        seen_.reset_cleared |= was_latched;
        if (was_latched) {
          RC_ASSERT(sup_.state() == AxisState::disabled);
          // Reset succeeds only when no persistent condition is present now.
          RC_ASSERT((present & kPersistent) == 0);
        }
        RC_ASSERT(state_before != AxisState::init || sup_.state() != AxisState::init);
        break;
      case Refusal::starting:
        RC_ASSERT(sup_.state() == AxisState::init);
        break;
      case Refusal::estop_pressed:
        RC_ASSERT(sup_.state() == AxisState::estop);
        RC_ASSERT(answer.blocking == FaultReason::estop);
        break;
      case Refusal::cause_present:
        RC_ASSERT(sup_.state() == AxisState::fault || sup_.state() == AxisState::estop);
        // The one still there: a persistent class, and none present ranks before it.
        RC_ASSERT((bit(answer.blocking) & kPersistent) != 0);
        RC_ASSERT(first_of(present & kPersistent) == FaultReason::none ||
                  answer.blocking <= first_of(present & kPersistent));
        break;
      default:
        RC_FAIL("a reset refused with a reason that is not a reset's");
    }
    // A persistent condition present trips, or is the latched state's cause: either way the
    // reset is handled in FAULT or ESTOP with it present, and refused.
    if ((present & kPersistent) != 0) RC_ASSERT(!answer.accepted);
  }

  void unchanged(const Decision& d, const Decision& d_without, const AxisSupervisor& without) {
    RC_ASSERT(same(d, d_without));
    RC_ASSERT(sup_.state() == without.state());
    RC_ASSERT(sup_.mode() == without.mode());
    RC_ASSERT(same(sup_.fault(), without.fault()));
    RC_ASSERT(sup_.active_faults() == without.active_faults());
    RC_ASSERT(sup_.faults_tripped() == without.faults_tripped());
    RC_ASSERT(sup_.setpoints_received() == without.setpoints_received());
    RC_ASSERT(sup_.soft_limits_armed() == without.soft_limits_armed());
  }

  // The loop's reaction to a non-finite command in a cycle that drove.
  void output_not_finite(double command) {
    const FaultRecord fault_before = sup_.fault();
    sup_.output_not_finite(command, t_);
    if (last_drive_) {
      RC_ASSERT(sup_.state() == AxisState::fault);
      RC_ASSERT(sup_.fault().reason == FaultReason::control_output);
    } else {
      RC_ASSERT(same(fault_before, sup_.fault()));  // not driving: nothing to catch
    }
    last_drive_ = false;
  }

  AxisSupervisor sup_{kParams};
  Model model_;
 public:
  // What a sequence reached, for the distribution rapidcheck prints: evidence that the
  // properties were judged where they matter.
  struct Seen {
    bool drove = false;
    bool tripped_driving = false;
    bool estop = false;
    bool refused = false;
    bool reset_cleared = false;
  } seen_;

 private:
  SupervisorInputs in_;
  AxisInputsFromOperator op_;
  AxisCommand last_op_command_{};
  std::uint64_t command_seq_ = 0;
  std::uint64_t handled_seq_ = 0;
  bool frozen_[kSignals]{};
  bool last_drive_ = false;
  std::int64_t t_ = 0;
};

RC_GTEST_PROP(AxisSupervisorProperties, HoldAfterEveryEventOfARandomSequence, ()) {
  const auto events = *rc::gen::resize(kMaxEvents, rc::gen::container<std::vector<Event>>(event_gen()));
  Rig rig;
  for (const Event& e : events) rig.apply(e);
  const Rig::Seen& seen = rig.seen_;
  RC_CLASSIFY(seen.drove, "drove");
  RC_CLASSIFY(seen.tripped_driving, "tripped while driving");
  RC_CLASSIFY(seen.estop, "ESTOP");
  RC_CLASSIFY(seen.refused, "refused a command");
  RC_CLASSIFY(seen.reset_cleared, "reset cleared a fault");
}

}  // namespace
}  // namespace hsa::daemon
