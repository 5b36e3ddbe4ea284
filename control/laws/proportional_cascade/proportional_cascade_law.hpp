// The position law for a proportional valve: the cylinder PI of Puglisi et al. (2015) gives the
// opening u, which maps onto a spool position reference (u · spool_at_full_opening_m); the state
// predictor of Canuto et al. (2014), eqs 15–16, and the valve law, eq 31, turn it into the
// solenoid current reference. In open loop the operator's opening takes the PI's place above the
// same predictor and valve law. Configured with drive = "proportional", an [axes.pi] table and an
// [axes.valve_law] table; the axis needs a spool signal.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "control/laws/pi_cascade_law.hpp"

namespace hsa::control {

// Bounds of the [axes.valve_law] numbers: solenoid currents and the law's gains.
namespace valve_law_bounds {
inline constexpr double kMaxCurrentA = 10.0;
inline constexpr double kMaxGain = 1e9;  // A per m, per m/s, per m/s², per m/s³, per (m s)
}  // namespace valve_law_bounds

class ProportionalCascadeLaw final : public PiCascadeLaw {
 public:
  static constexpr std::array<std::string_view, 2> kTables{"pi", "valve_law"};  // axis-level tables it reads
  static constexpr std::string_view kName = "proportional";

  // `params.drive` must be proportional. Throws std::invalid_argument as PiCascadeLaw does.
  ProportionalCascadeLaw(const CascadeParams& params, const GainBounds& bounds,
                         std::shared_ptr<const GainGate> gate = nullptr);

  // Reads [axes.pi] and [axes.valve_law] of the axis table `axis`.
  static std::unique_ptr<ControlLaw> from_settings(const LawSettings& axis, const LawTiming& timing);

  [[nodiscard]] std::unique_ptr<ControlLaw> clone() const override;
  [[nodiscard]] std::string_view name() const noexcept override { return kName; }
  [[nodiscard]] bool needs_spool() const noexcept override { return true; }
  [[nodiscard]] double null_command() const noexcept override;
  [[nodiscard]] std::string_view command_unit() const noexcept override { return " A"; }
  [[nodiscard]] std::string safe_command_refusal(double command, double band) const override;
  [[nodiscard]] std::string describe() const override;
  // The valve law's current at 0 or I_max (Canuto et al. 2014, eq 31): the command the valve gets.
  // The PI's opening may sit at its limit while the spool loop still has current in hand.
  [[nodiscard]] bool saturated() const noexcept override;
};

}  // namespace hsa::control
