#include "sim/rig.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/random.hpp"

namespace hsa::sim {
namespace {

ProportionalValveParameters seeded(ProportionalValveParameters p, std::uint64_t seed) {
  p.seed = derive_seed(seed, 2);
  return p;
}

const RigConfig& validated(const RigConfig& c) {
  const double stroke = c.cylinder.geometry.stroke_m;
  if (!(c.step_s > 0.0 && c.step_s <= 1e-3))
    throw std::invalid_argument("sim: step_s must be in (0, 1e-3] s, got " + std::to_string(c.step_s));
  if (!(c.load_kg >= 0.0))
    throw std::invalid_argument("sim: load_kg must be >= 0, got " + std::to_string(c.load_kg));
  if (!(c.initial_position_m >= 0.0 && c.initial_position_m <= stroke))
    throw std::invalid_argument("sim: initial_position_m must be within [0, " + std::to_string(stroke) +
                                "] m, got " + std::to_string(c.initial_position_m));
  return c;
}

}  // namespace

Rig::Rig(const RigConfig& config)
    : config_(validated(config)),
      load_kg_(config.load_kg),
      cylinder_model_(config.cylinder, config.supply),
      servo_(config.servo_valve),
      proportional_(seeded(config.proportional_valve, config.seed), config.step_s),
      sensors_(config.sensors, config.step_s, config.seed) {
  cylinder_ = cylinder_model_.rest_state(config.initial_position_m, load_kg_);
  servo_.reset(0.0);
  proportional_.reset(0.0);
  // Start at rest: a servo-valve centred, a proportional valve holding hydraulic zero.
  command_ = config.valve == ValveKind::servo ? 0.0 : proportional_.bias_current();
  sensors_.reset(sensed());
}

void Rig::set_valve_command(double command) { command_ = command; }
void Rig::set_valve_enable(bool enabled) { valve_enabled_ = enabled; }
void Rig::set_estop(bool pressed) { estop_ = pressed; }

bool Rig::set_load_mass(double kg) noexcept {
  if (!(kg >= 0.0)) return false;
  load_kg_ = kg;
  return true;
}

double Rig::valve_opening() const {
  return config_.valve == ValveKind::servo ? servo_.opening() : proportional_.opening();
}

SensedQuantities Rig::sensed() const {
  return {cylinder_.position_m, cylinder_.pressure_a_pa, cylinder_.pressure_b_pa, proportional_.position(),
          proportional_.current()};
}

void Rig::step() {
  const double dt = config_.step_s;
  // A disabled amplifier drives nothing: the servo-valve centres, the solenoid is unpowered and
  // its spring returns the spool to its rest stop.
  const double command = valve_enabled_ ? command_ : 0.0;
  if (config_.valve == ValveKind::servo) {
    servo_.set_stuck(faults_.valve_stuck);
    servo_.step(command, dt);
  } else {
    proportional_.set_stuck(faults_.valve_stuck);
    proportional_.step(command);
  }
  cylinder_model_.step(cylinder_, valve_opening(), load_kg_, !faults_.supply_lost, dt);
  sensors_.sample(sensed(), faults_);
  time_s_ += dt;
}

void Rig::advance(double duration_s) {
  const long long steps = std::llround(duration_s / config_.step_s);
  for (long long i = 0; i < steps; ++i) step();
}

RigReadings Rig::read() const {
  return {sensors_.encoder(), sensors_.pressure_a(), sensors_.pressure_b(), sensors_.spool_lvdt(),
          sensors_.valve_current(), estop_};
}

}  // namespace hsa::sim
