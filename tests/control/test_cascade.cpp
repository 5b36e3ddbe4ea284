#include "control/cascade.hpp"

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <stdexcept>

#include <gtest/gtest.h>

// Counts every heap allocation in this test program, so a test can assert that a stretch of
// loop code allocates nothing (DESIGN.md: no allocation after construction in control/).
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace hsa::control {
namespace {

constexpr double kExact = 1e-12;

CascadeParams direct_params() {
  CascadeParams p;
  p.drive = ValveDrive::direct;
  return p;
}

CascadeParams proportional_params() {
  CascadeParams p;
  p.valve.bias_current_a = 1.2;
  p.valve.feedforward_a_per_m = 250.0;
  p.valve.proportional_a_per_m = 3300.0;
  return p;
}

TEST(Cascade, DefaultsAreTheDesignRates) {
  const CascadeParams p;
  EXPECT_EQ(p.cylinder.period_s, 1e-3);
  EXPECT_EQ(p.valve.period_s, 1e-4);
  EXPECT_EQ(p.valve_ticks_per_cylinder_tick, 10u);
  EXPECT_NO_THROW(Cascade{p});
}

TEST(Cascade, RunsThePiOnceEveryTenValveTicksAndHoldsItsOpening) {
  Cascade c(direct_params());
  c.activate(0.1, 0.0);
  int runs = 0;
  double held = 0.0;
  for (int k = 0; k < 100; ++k) {
    // A setpoint that changes every tick: only the ticks that run the PI may see it.
    const CascadeOutput out = c.tick({.rod_setpoint_m = 0.1 + 1e-6 * k, .rod_position_m = 0.1});
    EXPECT_EQ(out.cylinder_ticked, k % 10 == 0) << "tick " << k;
    if (out.cylinder_ticked) {
      ++runs;
      held = out.opening;
      EXPECT_NEAR(c.cylinder().limited_setpoint(), 0.1 + 1e-6 * k, kExact);
    }
    EXPECT_EQ(out.opening, held);
  }
  EXPECT_EQ(runs, 10);
}

TEST(Cascade, DirectModeOutputsTheOpening) {
  Cascade c(direct_params());
  c.activate(0.05, 0.0);
  const CascadeOutput out = c.tick({.rod_setpoint_m = 0.051, .rod_position_m = 0.05, .spool_position_m = 7.0});
  EXPECT_NEAR(out.opening, (85.0 + 0.46) * 1e-3, kExact);
  EXPECT_EQ(out.command, out.opening);
}

TEST(Cascade, ActivationIsBumplessInBothModes) {
  for (const CascadeParams& p : {direct_params(), proportional_params()}) {
    Cascade c(p);
    const double rod = 0.2, opening = 0.4;
    const double spool = opening * 1.25e-3;  // the spool sits where the opening puts it
    c.activate(rod, spool, opening);
    const CascadeOutput out = c.tick({.rod_setpoint_m = rod, .rod_position_m = rod, .spool_position_m = spool});
    EXPECT_NEAR(out.opening, opening, kExact);
    if (p.drive == ValveDrive::direct) {
      EXPECT_NEAR(out.command, opening, kExact);
    } else {
      // Spool on its reference and at rest: only bias and feedforward remain.
      EXPECT_NEAR(out.command, 1.2 + 250.0 * spool, kExact);
    }
  }
}

TEST(Cascade, OpeningMapsLinearlyOntoTheSpoolStroke) {
  Cascade c(proportional_params());
  for (const double opening : {-1.0, -0.5, 0.0, 0.25, 1.0}) {
    c.activate(0.1, 0.0, opening);
    const CascadeOutput out = c.tick({.rod_setpoint_m = 0.1, .rod_position_m = 0.1});
    EXPECT_NEAR(out.spool_reference_m, opening * 1.25e-3, kExact);
    // The spool sits at zero: the valve law sees the reference as its error.
    EXPECT_NEAR(c.valve().error(), opening * 1.25e-3, kExact);
  }
}

TEST(Cascade, TicksWithoutAllocating) {
  for (const CascadeParams& p : {direct_params(), proportional_params()}) {
    Cascade c(p);
    const long before = g_allocations.load();
    c.activate(0.1, 0.0);
    double sum = 0.0;
    for (int k = 0; k < 10000; ++k) {
      sum += c.tick({.rod_setpoint_m = 0.12, .rod_position_m = 0.1 + 1e-7 * k, .spool_position_m = 1e-5}).command;
    }
    EXPECT_EQ(g_allocations.load(), before);
    EXPECT_TRUE(std::isfinite(sum));
  }
}

TEST(Cascade, RejectsInconsistentRates) {
  CascadeParams p;
  p.cylinder.period_s = 2e-3;
  EXPECT_THROW(Cascade{p}, std::invalid_argument);
  p.valve_ticks_per_cylinder_tick = 20;
  EXPECT_NO_THROW(Cascade{p});
  p.valve_ticks_per_cylinder_tick = 0;
  EXPECT_THROW(Cascade{p}, std::invalid_argument);
}

}  // namespace
}  // namespace hsa::control
