#include "daemon/hsad/excitation_gate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "control/loop_analysis.hpp"
#include "control/plant_table.hpp"
#include "daemon/axis/port_messages.hpp"

namespace hsa::daemon::excitation_gate {
namespace {

std::string format(const char* fmt, auto... values) {
  char text[kReasonSize];  // what a command's answer in status holds
  std::snprintf(text, sizeof text, fmt, values...);
  return text;
}

// The largest no-load rod speed at full opening of Table A3, m/s.
double largest_k01_m_s() {
  double k01_mm_s = 0.0;
  for (const control::IdentifiedPlant& row : control::kTableA3) k01_mm_s = std::max(k01_mm_s, row.k01);
  return k01_mm_s * control::kMetresPerMillimetre;
}

}  // namespace

WorstMargin worst_gain_margin(double kp_per_m) {
  WorstMargin worst{.gain_margin_db = INFINITY};
  for (const control::IdentifiedPlant& row : control::kTableA3) {
    const double gm = control::stability_margins(row.plant(), {.kp = kp_per_m, .ki = 0.0}).gain_margin_db;
    if (gm < worst.gain_margin_db) worst = {gm, row.position_mm, row.load_kg, row.b1 / row.k01};
  }
  return worst;
}

std::string refusal(const ExcitationRequest& r, const SupervisorParams& axis, double rod_m) {
  constexpr double mm = 1e3;
  if (r.switching_time_s < kMinSwitchingS) {
    return format("switching time %.4g s under %.3g s: the cylinder loop would hold a level for fewer than 10 samples",
                  r.switching_time_s, kMinSwitchingS);
  }
  if (r.switching_time_s > r.duration_s) {
    return format("switching time %.4g s longer than the duration %.4g s", r.switching_time_s, r.duration_s);
  }
  const double low = r.working_point_m - r.amplitude_m;
  const double high = r.working_point_m + r.amplitude_m;
  if (!(low >= axis.soft_limit_low_m && high <= axis.soft_limit_high_m)) {
    return format("excitation %.3f..%.3f mm (working point %.3f mm ± %.3f mm) outside the soft limits [%.2f, %.2f] mm",
                  low * mm, high * mm, r.working_point_m * mm, r.amplitude_m * mm, axis.soft_limit_low_m * mm,
                  axis.soft_limit_high_m * mm);
  }
  const double approach_m = std::abs(r.working_point_m - rod_m) + r.amplitude_m;
  const double step_m = std::max(2.0 * r.amplitude_m, approach_m);
  const bool approach = step_m > 2.0 * r.amplitude_m;
  const char* which = approach ? "from the rod to the first level" : "between levels (2 x amplitude)";
  const char* hint = approach ? " (move the rod to the working point first)" : "";
  if (!(step_m < axis.following_error_max_m)) {
    return format("a setpoint step of %.3f mm %s makes a following error of about that much, not under "
                  "max_following_error_m %.3f mm%s",
                  step_m * mm, which, axis.following_error_max_m * mm, hint);
  }
  const double opening = std::min(r.kp_per_m * step_m, 1.0);
  const double speed_m_s = opening * largest_k01_m_s();
  if (speed_m_s > axis.max_speed_m_s) {
    return format("a setpoint step of %.3f mm %s at kp %.4g /m: opening %.2f, about %.1f mm/s at Table A3's "
                  "no-load %.0f mm/s, over max_speed_m_s %.1f mm/s%s",
                  step_m * mm, which, r.kp_per_m, opening, speed_m_s * mm, largest_k01_m_s() * mm,
                  axis.max_speed_m_s * mm, hint);
  }
  const WorstMargin worst = worst_gain_margin(r.kp_per_m);
  if (!(worst.gain_margin_db >= kMinGainMarginDb)) {
    return format("kp %.4g /m (%.4g per mm) leaves a gain margin of %.2f dB on the plant at %d mm with %d kg (Table "
                  "A3; Routh: stable below b1/k01 = %.3f per mm), under the %.1f dB an excitation needs",
                  r.kp_per_m, r.kp_per_m * control::kMetresPerMillimetre, worst.gain_margin_db, worst.position_mm,
                  worst.load_kg, worst.routh_limit_per_mm, kMinGainMarginDb);
  }
  return "";
}

}  // namespace hsa::daemon::excitation_gate
