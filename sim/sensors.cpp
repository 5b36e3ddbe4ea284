#include "sim/sensors.hpp"

#include <cmath>
#include <limits>

#include "sim/random.hpp"

namespace hsa::sim {
namespace {

LvdtParameters seeded(LvdtParameters p, std::uint64_t seed) {
  p.seed = derive_seed(seed, 0);
  return p;
}

}  // namespace

Sensors::Sensors(const SensorParameters& parameters, double step_s, std::uint64_t seed)
    : parameters_(parameters), lvdt_(seeded(parameters.lvdt, seed), step_s), rng_(derive_seed(seed, 1)) {}

void Sensors::reset(const SensedQuantities& truth) {
  lvdt_.reset(truth.spool_position_m);
  sample(truth, FaultInjection{});
}

void Sensors::apply(SensorReading& out, double measured, const SensorFault& fault) {
  switch (fault.mode) {
    case SensorFaultMode::stuck:
      out.connected = true;  // the last value stays
      if (std::isnan(out.value)) out.value = measured;
      return;
    case SensorFaultMode::disconnected:
      out = {std::numeric_limits<double>::quiet_NaN(), false};
      return;
    case SensorFaultMode::none:
      break;
  }
  if (fault.extra_noise_std > 0.0) measured += fault.extra_noise_std * unit_normal_(rng_);
  out = {measured, true};
}

void Sensors::sample(const SensedQuantities& truth, const FaultInjection& faults) {
  const double res = parameters_.encoder_resolution_m;
  const double counts = res > 0.0 ? std::round(truth.position_m / res) * res : truth.position_m;
  apply(encoder_, counts, faults.encoder);

  const double noise = parameters_.pressure_noise_std_pa;
  apply(pressure_a_, truth.pressure_a_pa + noise * unit_normal_(rng_), faults.pressure_a);
  apply(pressure_b_, truth.pressure_b_pa + noise * unit_normal_(rng_), faults.pressure_b);

  lvdt_.step(truth.spool_position_m);
  apply(spool_lvdt_, lvdt_.value(), faults.spool_lvdt);
  apply(valve_current_, truth.solenoid_current_a, faults.valve_current);
}

}  // namespace hsa::sim
