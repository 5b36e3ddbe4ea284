// The position law for a proportional valve: the cylinder PI of Puglisi et al. (2015) gives the
// opening u, which maps onto a spool position reference (u · spool_at_full_opening_m); the state
// predictor of Canuto et al. (2014), eqs 15–16, and the valve law, eq 31, turn it into the
// solenoid current reference. In open loop the operator's opening takes the PI's place above the
// same predictor and valve law. With [axes.valve_law.predictive] the predictive law
// (control/valve_predictive.hpp) decides the current in eq 31's place, from the spool reference and
// the LVDT reading alone. Configured with drive = "proportional", an [axes.pi] table and an
// [axes.valve_law] table; the axis needs a spool signal.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "control/laws/pi_cascade_law.hpp"
#include "control/valve_predictive_design.hpp"

namespace hsa::control {

// Bounds of the [axes.valve_law] numbers: solenoid currents and the law's gains.
namespace valve_law_bounds {
inline constexpr double kMaxCurrentA = 10.0;
inline constexpr double kMaxGain = 1e9;  // A per m, per m/s, per m/s², per m/s³, per (m s)
// [axes.valve_law.predictive]. At load the design builds H + 1 powers of the n × n plant with its
// reference registers, n = 6 + D + 2·(P + 1), and iterates two Riccati recursions to their steady
// state; every tick the law solves a QP in H commands within ValvePredictiveLaw::kQpWorkBudget
// multiply-adds (the reader checks H·n against it). At P = H − P = 100 with D = 16 (the most the
// delay line holds) valve_predictive_params() takes about 2 s and 85 MB on the project's 2-core VM
// for a valve like the paper's (more for a slow one: 9 s for a magnetic lag of 100 s); the
// design's grid chooses P in {16, 28} and H − P = 50 (20 ms).
inline constexpr int kMaxPreviewSamples = 100;
inline constexpr int kMaxHorizonExtraSamples = 100;
// ρ prices a step of 1 A in the command like √ρ m of tracking error: 10⁻⁸ m²/A² prices it like
// 100 µm, ten times the peak residual Canuto et al. (2014) Table 3 allows, and 50 times the grid's
// largest (2·10⁻¹⁰). The control Riccati recursion also settles more slowly as ρ grows.
inline constexpr double kMaxRateWeightM2PerA2 = 1e-8;
// The QP's steps a tick, after which its commands are clamped to the box: the design's 200 times 5,
// against a slip of an order of magnitude. The law's work budget stops a sample's steps sooner.
inline constexpr int kMaxQpIterations = 1000;
}  // namespace valve_law_bounds

// What [axes.valve_law.predictive] gave the design (control/valve_predictive_design.hpp), kept beside
// the matrices valve_predictive_params() built from it: they no longer show ρ, the random walks or
// most of the identified valve, and describe() says what the law was built on.
struct ValvePredictiveSource {
  ValvePredictiveValve valve;
  ValvePredictiveSettings settings;
};

class ProportionalCascadeLaw final : public PiCascadeLaw {
 public:
  static constexpr std::array<std::string_view, 2> kTables{"pi", "valve_law"};  // axis-level tables it reads
  static constexpr std::string_view kName = "proportional";

  // `params.drive` must be proportional. Throws std::invalid_argument as PiCascadeLaw does, and for
  // a `predictive` source without params.valve.predictive enabled. `predictive`: what the
  // predictive law's matrices were built from, for describe(); a law built in code may leave it out.
  ProportionalCascadeLaw(const CascadeParams& params, const GainBounds& bounds,
                         std::shared_ptr<const GainGate> gate = nullptr,
                         std::optional<ValvePredictiveSource> predictive = std::nullopt);

  // Reads [axes.pi] and [axes.valve_law] (with its model, time_optimal or predictive table) of the
  // axis table `axis`.
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

 private:
  std::optional<ValvePredictiveSource> predictive_;
};

}  // namespace hsa::control
