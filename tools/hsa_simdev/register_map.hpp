// hsa-simdev's Modbus register map: where the simulated rig's I/O lives on the wire. Tests,
// example configurations and anyone with mbpoll read it from here.
//
// 32-bit values span two registers, most significant word first ("ABCD"; mbpoll -B, modbus
// plugin word_order = "high_first"). Addresses are 0-based protocol addresses (mbpoll -0).
//
// Input registers (function 04):
//    0-1   float32  rod position             m
//    2-3   float32  pressure chamber A       Pa (gauge)
//    4-5   float32  pressure chamber B       Pa (gauge)
//    6-7   float32  spool LVDT               m    proportional valve only, else 0
//    8-9   float32  measured valve current   A    proportional valve only, else 0
//   10-11  float32  simulated time           s    advances in real time: a liveness check
//   20-21  int32    rod position             1 µm per count
//   22-23  int32    pressure chamber A       1 Pa per count
//   24-25  int32    pressure chamber B       1 Pa per count
//   30     uint16   sensor connected bits    bit 0 encoder, 1 pressure A, 2 pressure B,
//                                            3 spool LVDT, 4 valve current (proportional only)
//   40     uint16   watchdog tripped         1 = latched: valve command 0, enable off (below)
//   41     uint16   watchdog trips           since start, wraps at 65536
//   42     uint16   watchdog time            ms, as set by --watchdog-ms; 0 = off
//   43     uint16   foreign output writes    writes to the valve command or enable refused because
//                                            they came from a connection that is not the master
//                                            (below); wraps at 65536
//   44     uint16   valve power cut          1 = the e-stop has cut the valve's power (below)
//   45     uint16   refused command writes   the master's valve command writes refused while coil 9
//                                            is set (below); wraps at 65536
// A disconnected sensor reads NaN in float32 and 0 in int32, with its bit cleared.
//
// Holding registers (functions 03, 06, 16):
//    0-1   float32  valve command            servo-valve: opening in [-1, 1];
//                                            proportional: solenoid current reference, A
//    2     uint16   master heartbeat         kept as written, no effect on the rig: where a
//                                            master's heartbeat counter goes (the modbus plugin's
//                                            `heartbeat = true`), so that a monitor can see when
//                                            the master's cycle stopped
// Coils (functions 01, 05, 15):
//    0              valve amplifier enable   0 at start: the valve is unpowered until enabled
//    8              e-stop button            1 = pressed (a test hook: the rig's button)
//    9              refuse valve command     1 = the master's valve command writes are refused
//                                            (a test hook: a device refusing a value; below)
// Discrete inputs (function 02):
//    0              e-stop loop closed       1 = not pressed, as wired (active low)
//    1              watchdog tripped         as input register 40
//
// The master: the connection that first writes an output (the valve command registers 0-1 or the
// enable coil 0) owns the outputs until it closes. Another connection's writes to them are refused
// with exception 01 (illegal function: not allowed in the device's current state) and counted in
// input register 43; it may still write the heartbeat register and the e-stop button, and read
// everything. Without this a monitor's writes would keep a dead master's valve command alive.
//
// Communication watchdog (--watchdog-ms, default 100; rig_runner.hpp, comm_watchdog.hpp): armed
// by the master's first write. Every request with a write function code (05, 06, 15, 16, 22, 23)
// from the master feeds it; reads do not, and nothing another connection sends does. No write from
// the master for the watchdog time: the valve command goes to 0.0 and the enable off, and that
// latches (input register 40, discrete input 1). While latched the holding register and the coil
// read back 0 whatever is written to them. The master clears the latch by writing the enable coil
// 0 (function 05 or 15); a later write of 1 powers the valve again. hsad does this by itself: its
// modbus plugin writes the enable off before activation and while the axis is not enabled. When the
// master's connection closes, the next connection to write an output becomes the master (a
// restarted hsad), and only its enable-off clears a latch. Once a CAN valve frame has arrived
// (can_server.hpp) the watchdog watches CAN instead.
//
// Refusing the valve command (coil 9, a test hook any connection may write, the master included):
// while it is 1, every write of the master that touches the valve command (holding registers 0-1)
// is refused with exception 03 (illegal data value), as a device refuses a value it will not take,
// and counted in input register 45. A refused write changes nothing: not the command, not the
// watchdog. The enable coil and the heartbeat are still taken, so the master can still switch the
// valve off; a write of 0 to the coil ends the refusal. Another connection's command writes are
// refused as before (exception 01), whatever the coil says: the outputs are the master's.
//
// E-stop (coil 8): pressing it opens the loop (discrete input 0 reads 0) and, as an e-stop chain
// does, cuts the valve amplifier's power: the valve goes to rest and the rod stops, whatever the
// master writes (input register 44). The cut holds until the button is released and the master
// writes the enable off, as a safety relay waits for its reset; then an enable on powers the valve
// again. `--estop-signal-only` models a rig whose e-stop circuit does not reach the valve: the
// button then changes only the e-stop input.
#pragma once

namespace hsa::simdev {

namespace input_register {
inline constexpr int position_m = 0;
inline constexpr int pressure_a_pa = 2;
inline constexpr int pressure_b_pa = 4;
inline constexpr int spool_lvdt_m = 6;
inline constexpr int valve_current_a = 8;
inline constexpr int time_s = 10;
inline constexpr int position_um_i32 = 20;
inline constexpr int pressure_a_pa_i32 = 22;
inline constexpr int pressure_b_pa_i32 = 24;
inline constexpr int sensor_bits = 30;
inline constexpr int watchdog_tripped = 40;
inline constexpr int watchdog_trips = 41;
inline constexpr int watchdog_ms = 42;
inline constexpr int foreign_writes = 43;
inline constexpr int valve_power_cut = 44;
inline constexpr int refused_command_writes = 45;
inline constexpr int count = 46;
}  // namespace input_register

namespace holding_register {
inline constexpr int valve_command = 0;
inline constexpr int master_heartbeat = 2;
inline constexpr int count = 3;
}  // namespace holding_register

namespace coil {
inline constexpr int valve_enable = 0;
inline constexpr int estop_button = 8;
inline constexpr int refuse_valve_command = 9;
inline constexpr int count = 10;
}  // namespace coil

namespace discrete_input {
inline constexpr int estop_loop_closed = 0;
inline constexpr int watchdog_tripped = 1;
inline constexpr int count = 2;
}  // namespace discrete_input

}  // namespace hsa::simdev
