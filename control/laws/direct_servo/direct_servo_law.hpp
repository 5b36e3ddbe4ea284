// The position law for a servo-valve with its own spool electronics: the cylinder PI of Puglisi
// et al. (2015) section 4.2 sends its opening u ∈ [-1, 1] to the valve as the command. There is no
// valve loop, so no spool signal is needed; in open loop the operator's opening is the command.
// Configured with drive = "direct" and an [axes.pi] table.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "control/laws/pi_cascade_law.hpp"

namespace hsa::control {

class DirectServoLaw final : public PiCascadeLaw {
 public:
  static constexpr std::array<std::string_view, 1> kTables{"pi"};  // axis-level tables it reads
  static constexpr std::string_view kName = "direct";

  // `pi` with its period, and the runtime gain bounds. Throws std::invalid_argument as
  // PiCascadeLaw does.
  DirectServoLaw(const PiParams& pi, std::uint32_t ticks_per_cylinder_tick, const GainBounds& bounds,
                 std::shared_ptr<const GainGate> gate = nullptr);

  // Reads [axes.pi] of the axis table `axis`; `timing` sets the PI's period.
  static std::unique_ptr<ControlLaw> from_settings(const LawSettings& axis, const LawTiming& timing);

  [[nodiscard]] std::unique_ptr<ControlLaw> clone() const override;
  [[nodiscard]] std::string_view name() const noexcept override { return kName; }
  [[nodiscard]] bool needs_spool() const noexcept override { return false; }
  [[nodiscard]] double null_command() const noexcept override;
  [[nodiscard]] std::string_view command_unit() const noexcept override { return ""; }
  [[nodiscard]] std::string safe_command_refusal(double command, double band) const override;
  [[nodiscard]] std::string describe() const override;
};

}  // namespace hsa::control
