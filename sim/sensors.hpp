// The rig's sensors as the DS1103 board saw them (Puglisi et al. 2015, section 3.3) plus the proportional
// valve's LVDT and current measurement (Canuto et al. 2014, eqs 1 and 7):
// - rod encoder: the position quantized to its resolution (default 1 µm);
// - pressure transducers on ports A and B: the chamber pressure plus white noise;
// - spool LVDT: LvdtSensor (500 Hz bandwidth, excitation ripple, noise);
// - solenoid current: the regulator's measured current (ProportionalValve::current()).
// Each can be faulted (faults.hpp): frozen, disconnected, or noisier.
#pragma once

#include <cstdint>
#include <random>

#include "sim/faults.hpp"
#include "sim/lvdt_sensor.hpp"

namespace hsa::sim {

struct SensorParameters {
  double encoder_resolution_m = 1e-6;
  double pressure_noise_std_pa = 2e3;  // 0.02 bar, a 0.1 % transducer on a 25 bar range
  LvdtParameters lvdt{};

  friend bool operator==(const SensorParameters&, const SensorParameters&) = default;
};

struct SensorReading {
  double value = 0.0;  // SI; NaN while disconnected
  bool connected = true;
};

// The true quantities the sensors look at, after a step.
struct SensedQuantities {
  double position_m;
  double pressure_a_pa;
  double pressure_b_pa;
  double spool_position_m;
  double solenoid_current_a;
};

class Sensors {
 public:
  Sensors(const SensorParameters& parameters, double step_s, std::uint64_t seed);

  void reset(const SensedQuantities& truth);
  void sample(const SensedQuantities& truth, const FaultInjection& faults);

  [[nodiscard]] const SensorReading& encoder() const { return encoder_; }
  [[nodiscard]] const SensorReading& pressure_a() const { return pressure_a_; }
  [[nodiscard]] const SensorReading& pressure_b() const { return pressure_b_; }
  [[nodiscard]] const SensorReading& spool_lvdt() const { return spool_lvdt_; }
  [[nodiscard]] const SensorReading& valve_current() const { return valve_current_; }

 private:
  // Applies a fault to a fresh measurement and stores it in `out`.
  void apply(SensorReading& out, double measured, const SensorFault& fault);

  SensorParameters parameters_;
  LvdtSensor lvdt_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  SensorReading encoder_, pressure_a_, pressure_b_, spool_lvdt_, valve_current_;
};

}  // namespace hsa::sim
