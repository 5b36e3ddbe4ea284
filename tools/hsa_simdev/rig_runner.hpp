// The simulated rig advancing in real time on its own thread, paced by clock_nanosleep
// (CLOCK_MONOTONIC, TIMER_ABSTIME) at a fixed period, each period stepping the rig by that much
// simulated time.
//
// The Modbus server thread exchanges values with it through a mutex-protected snapshot: this is a
// tool, not the daemon's RT path, and a lock held for a struct copy is cheaper than anything
// cleverer. When the process falls far behind (a stopped debugger, an overloaded machine) the
// runner skips ahead instead of racing to catch up, and counts the skips.
//
// It also holds the device's communication watchdog (comm_watchdog.hpp). It watches the valve's
// master: Modbus writes until the first CAN valve frame, CAN valve frames from then on. It is
// checked every period whether or not anything arrives: for Modbus by this thread, for CAN by the
// CAN thread right after it has drained its socket (check_can_watchdog), so that frames a stalled
// CAN thread has not yet read cannot be mistaken for silence. On a trip the
// valve command goes to 0.0 (the value hsa-simdev also uses for a garbage command: the valve at
// rest) and the enable off, in the rig and in the held inputs, and both stay there, whatever the
// master writes, until the master writes the enable off (acknowledge), through the interface
// that drives the valve. Then a later enable on powers the valve again.
//
// It also holds the e-stop chain's cut of the valve power (register_map.hpp): pressing the button
// cuts it in the next period, whatever the master writes; it is restored only once the button is
// released and the master has written the enable off, as a safety relay waits for its reset.
//
// With the delay probe on (enable_delay_probe, delay_probe.hpp), each tick's encoder sample is
// stamped on this thread at the tick, on CLOCK_MONOTONIC, and gets the probe's square wave added
// before anyone can serve it; the servers report each valve command the master wrote
// (note_valve_command) with the time they took it, on the same clock.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>

#include "sim/rig.hpp"
#include "tools/hsa_simdev/comm_watchdog.hpp"
#include "tools/hsa_simdev/delay_probe.hpp"

namespace hsa::simdev {

struct RigInputs {
  double valve_command = 0.0;
  bool valve_enable = false;
  bool estop_pressed = false;
};

struct RigOutputs {
  sim::RigReadings readings{};
  double time_s = 0.0;
};

struct WatchdogState {
  bool enabled = false;
  bool tripped = false;  // latched
  std::uint64_t trips = 0;
};

// What one Modbus request of the master did, for the watchdog and the e-stop's reset. A request
// from any other connection is no master write: it passes the default.
struct MasterWrite {
  bool any = false;             // a write function code: feeds the watchdog
  bool wrote_enable = false;    // it wrote the valve enable coil (to the value in RigInputs)
};

// How the rig's e-stop button acts.
enum class EstopWiring {
  cuts_valve_power,  // an e-stop chain: the button also removes the valve amplifier's power
  signal_only,       // the button only opens the e-stop input
};

class RigRunner {
 public:
  // watchdog_s: the communication watchdog's time; 0 turns it off.
  RigRunner(const sim::RigConfig& config, double period_s, double watchdog_s = 0.0,
            EstopWiring estop = EstopWiring::cuts_valve_power);
  ~RigRunner();  // stops the thread
  RigRunner(const RigRunner&) = delete;
  RigRunner& operator=(const RigRunner&) = delete;

  void start();
  void stop();

  // The inputs as a Modbus request left them. While the watchdog is tripped the valve command and
  // enable are held safe (see above); the returned inputs are those held, for the register map.
  RigInputs set_inputs(const RigInputs& inputs, const MasterWrite& write = {});
  // The valve command and enable from the CAN bus (can_server.hpp). From the first call on they
  // take precedence over those of set_inputs: two masters on one valve would fight, and a
  // controller that talks CAN to the valve does not write the Modbus register.
  // Each call is one received valve frame: it feeds the watchdog.
  void set_can_valve(double command, bool enable);
  // The CAN thread, every period after draining its socket.
  void check_can_watchdog();
  [[nodiscard]] WatchdogState watchdog() const;
  // True while the e-stop keeps the valve unpowered (see above).
  [[nodiscard]] bool valve_power_cut() const;
  [[nodiscard]] RigOutputs outputs() const;
  [[nodiscard]] std::uint64_t skips() const { return skips_.load(std::memory_order_relaxed); }

  // Before start(): the served position carries the probe's square wave from then on.
  void enable_delay_probe(const DelayProbeSettings& settings);
  // A server thread: the master's valve command, taken at `now_ns` (CLOCK_MONOTONIC).
  void note_valve_command(double command, std::int64_t now_ns);
  // The probe's results so far (a copy); empty when it is off.
  [[nodiscard]] std::optional<DelayProbe> delay_probe() const;

 private:
  void run(std::stop_token stop);
  void check_watchdog_locked();  // trips it when due: the held valve inputs go safe
  void update_estop_cut_locked(bool master_wrote_enable_off);

  sim::Rig rig_;  // the runner thread's alone once started
  double period_s_;
  mutable std::mutex mutex_;
  RigInputs inputs_;    // guarded by mutex_
  RigOutputs outputs_;  // guarded by mutex_
  bool can_valve_ = false;  // guarded by mutex_: set_can_valve was called
  double can_command_ = 0.0;
  bool can_enable_ = false;
  CommWatchdog watchdog_;  // guarded by mutex_
  const EstopWiring estop_wiring_;
  bool valve_power_cut_ = false;  // guarded by mutex_
  std::optional<DelayProbe> probe_;  // guarded by mutex_
  std::atomic<std::uint64_t> skips_{0};
  std::jthread thread_;
};

}  // namespace hsa::simdev
