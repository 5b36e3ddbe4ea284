// The simulated test rig of Puglisi et al. (2015): a vertical double-acting cylinder
// lifting a load, driven either by the Moog E050 servo-valve of Puglisi et al. (2015) or by the single-solenoid
// proportional valve of Canuto et al. (2014), with the sensors a DS1103 board read.
//
// The rig advances in simulated time only (lockstep): nothing here reads a clock or sleeps, so a
// test can run it far faster than real time and get the same trajectory for the same seed.
// One step() advances by the fixed internal step; advance() loops over whole steps.
#pragma once

#include <cstdint>

#include "sim/cylinder.hpp"
#include "sim/faults.hpp"
#include "sim/hydraulic_supply.hpp"
#include "sim/proportional_valve.hpp"
#include "sim/sensors.hpp"
#include "sim/servo_valve.hpp"

namespace hsa::sim {

enum class ValveKind {
  servo,         // Puglisi et al. (2015): command is the normalized opening in [-1, 1]
  proportional,  // Canuto et al. (2014): command is the solenoid current reference in [0, I_max] A
};

struct RigConfig {
  ValveKind valve = ValveKind::servo;
  double load_kg = 0.0;              // external load mass on the rod
  double initial_position_m = 0.150; // rod position at t = 0, in [0, stroke]
  double step_s = 1e-4;              // internal integration step (the daemon's base tick)
  std::uint64_t seed = 1;            // all noise derives from this seed
  CylinderParameters cylinder{};
  SupplyParameters supply{};
  ServoValveParameters servo_valve{};
  ProportionalValveParameters proportional_valve{};
  SensorParameters sensors{};

  friend bool operator==(const RigConfig&, const RigConfig&) = default;
};

// What the rig's sensors deliver, in SI units, before any I/O scaling.
struct RigReadings {
  SensorReading encoder_m;        // rod position, quantized
  SensorReading pressure_a_pa;    // chamber A (gauge)
  SensorReading pressure_b_pa;    // chamber B (gauge)
  SensorReading spool_lvdt_m;     // proportional valve spool position (LVDT, eq 7 of Canuto et al. (2014))
  SensorReading valve_current_a;  // measured solenoid current (proportional valve)
  bool estop_pressed = false;
};

class Rig {
 public:
  explicit Rig(const RigConfig& config);

  // Inputs, latched until changed. The command's meaning depends on the valve kind (see ValveKind).
  void set_valve_command(double command);
  void set_valve_enable(bool enabled);  // disabled: servo opening 0, solenoid current 0
  // May change during a run. Returns false, changing nothing, for a mass that is not >= 0 kg.
  bool set_load_mass(double kg) noexcept;
  void set_estop(bool pressed);

  void step();                      // one internal step of config().step_s
  void advance(double duration_s);  // whole steps covering duration_s (rounded to nearest)

  [[nodiscard]] RigReadings read() const;  // sensor outputs after the last step
  [[nodiscard]] double time_s() const { return time_s_; }
  [[nodiscard]] const CylinderState& cylinder_state() const { return cylinder_; }
  [[nodiscard]] const Cylinder& cylinder() const { return cylinder_model_; }
  [[nodiscard]] const ProportionalValve& proportional_valve() const { return proportional_; }
  [[nodiscard]] double valve_opening() const;  // normalized opening seen by the cylinder ports
  [[nodiscard]] const RigConfig& config() const { return config_; }
  [[nodiscard]] double load_mass() const { return load_kg_; }

  FaultInjection& faults() { return faults_; }
  [[nodiscard]] const FaultInjection& faults() const { return faults_; }

 private:
  [[nodiscard]] SensedQuantities sensed() const;

  RigConfig config_;
  double load_kg_;
  double command_ = 0.0;
  bool valve_enabled_ = true;
  bool estop_ = false;
  double time_s_ = 0.0;
  Cylinder cylinder_model_;
  CylinderState cylinder_{};
  ServoValve servo_;
  ProportionalValve proportional_;
  FaultInjection faults_{};
  Sensors sensors_;
};

}  // namespace hsa::sim
