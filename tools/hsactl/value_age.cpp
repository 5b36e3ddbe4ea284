#include "tools/hsactl/value_age.hpp"

#include <cstdio>

namespace hsa::ctl {

ValueAge status_position_age(const hsa::status_t& s) {
  if (s.position_age_us < 0) return {-1, static_cast<bool>(s.position_stale)};
  // A status stamped before its sample would be a daemon's bug; the age does not shrink for it.
  const std::int64_t since_sample = s.utime > s.sample_utime ? s.utime - s.sample_utime : 0;
  return {s.position_age_us + since_sample, static_cast<bool>(s.position_stale)};
}

std::array<InputAgeView, 5> telemetry_inputs(const hsa::telemetry_t& t) {
  const auto age = [&](std::int64_t us, int bit) { return ValueAge{us, (t.stale & bit) != 0}; };
  return {{
      {"position", "position", age(t.position_age_us, hsa::telemetry_t::STALE_POSITION)},
      {"pressure_a", "pressure A", age(t.pressure_a_age_us, hsa::telemetry_t::STALE_PRESSURE_A)},
      {"pressure_b", "pressure B", age(t.pressure_b_age_us, hsa::telemetry_t::STALE_PRESSURE_B)},
      {"spool", "spool", age(t.spool_age_us, hsa::telemetry_t::STALE_SPOOL)},
      {"estop", "e-stop", age(t.estop_age_us, hsa::telemetry_t::STALE_ESTOP)},
  }};
}

std::string age_text(const ValueAge& a) {
  if (a.age_us < 0) return "no such input";
  char text[48];
  if (a.age_us < 1'000'000) {
    std::snprintf(text, sizeof text, "%.1f ms old", static_cast<double>(a.age_us) / 1e3);
  } else {
    std::snprintf(text, sizeof text, "%.3f s old", static_cast<double>(a.age_us) / 1e6);
  }
  return a.stale ? std::string("STALE, ") + text : std::string(text);
}

std::string inputs_text(const hsa::telemetry_t& t) {
  std::string out;
  for (const InputAgeView& in : telemetry_inputs(t)) {
    if (in.age.age_us < 0) continue;
    out += (out.empty() ? "" : ", ") + std::string(in.name) + " " + age_text(in.age);
  }
  return out;
}

}  // namespace hsa::ctl
