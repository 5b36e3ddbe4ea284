// `hsa-analyze calibration`: the simulated rig's small-signal plant at each of the paper's 33
// working points, next to Table A3, with the relative deviations.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "control/plant_table.hpp"
#include "sim/calibration.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/json_list.hpp"

namespace hsa::analyze {
namespace {

void print_table(const std::vector<sim::CalibrationRow>& rows) {
  std::printf("%8s %6s | %8s %8s %6s | %6s %6s %5s | %6s %6s %6s\n", "pos[mm]", "load", "b0", "b0_tab",
              "dev%", "b1", "b1_tab", "dev%", "k01", "k01_tab", "dev%");
  for (const auto& r : rows) {
    std::printf("%8.0f %6.1f | %8.0f %8.0f %+6.2f | %6.1f %6.0f %+5.2f | %6.1f %6.0f %+6.2f\n",
                r.position_m * 1e3, r.load_kg, r.b0, r.b0_table, 100 * r.b0_deviation(), r.b1, r.b1_table,
                100 * r.b1_deviation(), r.k01, r.k01_table, 100 * r.k01_deviation());
  }
  const sim::CalibrationSummary worst = sim::worst_deviation(rows);
  std::printf("worst |deviation|: b0 %.2f %%, b1 %.2f %%, k01 %.2f %% (limit 10 %%)\n", 100 * worst.b0,
              100 * worst.b1, 100 * worst.k01);
}

void print_json(const std::vector<sim::CalibrationRow>& rows) {
  JsonList list;
  for (const sim::CalibrationRow& r : rows) {
    list.add({{"position_m", r.position_m}, {"load_kg", r.load_kg}, {"b0", r.b0}, {"b1", r.b1}, {"k01", r.k01},
              {"b0_table", r.b0_table}, {"b1_table", r.b1_table}, {"k01_table", r.k01_table}});
  }
  list.close();
}

}  // namespace

void add_calibration_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "calibration", "The simulated rig's small-signal plant at the paper's 33 working points vs Table A3");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "print a JSON list instead of a table");
  cmd->callback([json] {
    const std::vector<sim::CalibrationRow> rows =
        sim::calibration_table(sim::CylinderParameters{}, sim::SupplyParameters{}, control::kTableA3);
    if (*json) {
      print_json(rows);
    } else {
      print_table(rows);
    }
  });
}

}  // namespace hsa::analyze
