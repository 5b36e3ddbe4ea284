// The operator thread's checks of an excitation (daemon/hsad/excitation_gate.hpp): each bound
// refuses with its reason and numbers, and the paper's identification run passes them all.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "control/plant_table.hpp"
#include "daemon/hsad/excitation_gate.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;

// The limits of systemd/hsad-sim.toml.
SupervisorParams sim_axis() {
  SupervisorParams p;
  p.soft_limit_low_m = 0.010;
  p.soft_limit_high_m = 0.290;
  p.following_error_max_m = 0.020;
  p.max_speed_m_s = 0.2;
  return p;
}

// The run of tests/analyze/identification_run.hpp: ±1 mm PRMS at 150 mm, 0.3 s, kp 0.2 per mm.
ExcitationRequest paper_run() {
  return {.working_point_m = 0.150,
          .kind = control::ExcitationKind::prms,
          .amplitude_m = 1e-3,
          .switching_time_s = 0.3,
          .levels = 5,
          .seed = 3,
          .duration_s = 25.0,
          .kp_per_m = 200.0};
}

TEST(ExcitationGate, ThePapersIdentificationRunPasses) {
  EXPECT_EQ(excitation_gate::refusal(paper_run(), sim_axis(), 0.150), "");
}

TEST(ExcitationGate, TheGainMarginIsRouthsOnTheWorstPlantOfTableA3) {
  // Routh on s³ + b1·s² + b0·s + k01·b0·kp: the gain margin is b1/(k01·kp), kp per mm.
  double routh_worst_db = std::numeric_limits<double>::infinity();
  for (const control::IdentifiedPlant& row : control::kTableA3)
    routh_worst_db = std::min(routh_worst_db, 20.0 * std::log10(row.b1 / (row.k01 * 0.2)));
  const excitation_gate::WorstMargin worst = excitation_gate::worst_gain_margin(200.0);
  EXPECT_NEAR(worst.gain_margin_db, routh_worst_db, 0.01);
  EXPECT_EQ(worst.position_mm, 290);
  EXPECT_EQ(worst.load_kg, 6);
  EXPECT_GT(worst.gain_margin_db, excitation_gate::kMinGainMarginDb);
}

TEST(ExcitationGate, TooHighAGainIsRefusedNamingThePlantAndTheMargin) {
  ExcitationRequest r = paper_run();
  r.kp_per_m = 250.0;  // 0.25 per mm: 3.0 dB on the worst plant
  const std::string why = excitation_gate::refusal(r, sim_axis(), 0.150);
  EXPECT_THAT(why, HasSubstr("gain margin of 2.9"));
  EXPECT_THAT(why, HasSubstr("290 mm with 6 kg"));
  r.kp_per_m = 400.0;  // past Routh's limit on most plants: unstable
  r.amplitude_m = 0.5e-3;  // opening 0.4 at a step, within the speed bound
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150), HasSubstr("gain margin of -1.0"));
}

TEST(ExcitationGate, EachBoundRefusesWithItsReason) {
  ExcitationRequest r = paper_run();
  r.working_point_m = 0.2895;  // 290.5 mm over the 290 mm limit
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.2895), HasSubstr("outside the soft limits [10.00, 290.00] mm"));

  r = paper_run();
  r.amplitude_m = 0.012;  // a 24 mm step between levels
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150),
              HasSubstr("step of 24.000 mm between levels (2 x amplitude) makes a following error"));

  r = paper_run();
  r.working_point_m = 0.160;  // from a rod at 140 mm: 21 mm to the highest level
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.140), HasSubstr("from the rod to the first level"));
  // From 150 mm, 11 mm: within the following-error bound, but it opens the valve fully.
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150),
              HasSubstr("from the rod to the first level at kp 200 /m: opening 1.00, about 294.0 mm/s"));
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150), HasSubstr("move the rod to the working point first"));
  EXPECT_EQ(excitation_gate::refusal(r, sim_axis(), 0.1595), "");  // 1.5 mm away: the levels' 2 mm decide

  r = paper_run();
  r.amplitude_m = 0.005;  // 10 mm at 0.2 per mm: full opening, 294 mm/s
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150), HasSubstr("over max_speed_m_s 200.0 mm/s"));

  r = paper_run();
  r.switching_time_s = 0.005;
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150), HasSubstr("switching time"));
  r.switching_time_s = 30.0;
  EXPECT_THAT(excitation_gate::refusal(r, sim_axis(), 0.150), HasSubstr("longer than the duration"));
}

}  // namespace
}  // namespace hsa::daemon
