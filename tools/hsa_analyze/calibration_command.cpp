// `hsa-analyze calibration`: a simulated rig's small-signal plant (sim/small_signal.hpp) at
// working points, next to Table A3 where the paper identified one (on the paper's rig only), with
// the relative deviations.
// By default the papers' rig at Table A3's 33 points; --config takes the rig a hsad configuration's
// sim driver describes, read by the plugin's own reader (drivers/sim/rig_settings.hpp), so the
// plant is the one hsad would run; --points picks the working points.
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "control/plant_table.hpp"
#include "control/setting_range.hpp"
#include "daemon/config/load_config.hpp"
#include "drivers/sim/rig_settings.hpp"
#include "sim/calibration.hpp"
#include "tools/hsa_analyze/commands.hpp"
#include "tools/hsa_analyze/json_list.hpp"
#include "tools/hsa_analyze/working_point.hpp"

namespace hsa::analyze {
namespace {

constexpr double kNotIdentified = std::numeric_limits<double>::quiet_NaN();

// The rig of the configuration's sim driver: the one named, or the only one.
sim::RigConfig configured_rig(const std::string& file, const std::string& driver_name) {
  try {
    const daemon::DaemonConfig config = daemon::load_config(file);
    const daemon::DriverConfig* chosen = nullptr;
    std::string sim_drivers;
    for (const daemon::DriverConfig& d : config.drivers) {
      if (!driver_name.empty() ? d.name == driver_name : d.plugin == "sim") {
        if (chosen != nullptr && driver_name.empty()) {
          throw CLI::ValidationError("--driver", file + " has more than one sim driver (" + chosen->name + ", " +
                                                     d.name + "): name one");
        }
        chosen = &d;
      }
    }
    if (chosen == nullptr) {
      throw CLI::ValidationError(driver_name.empty() ? "--config" : "--driver",
                                 driver_name.empty() ? file + " has no driver with plugin = \"sim\""
                                                     : file + " has no driver named \"" + driver_name + "\"");
    }
    if (chosen->plugin != "sim") {
      throw CLI::ValidationError("--driver", "driver \"" + chosen->name + "\" runs plugin \"" + chosen->plugin +
                                                 "\"; only the sim plugin describes a rig model");
    }
    return io::sim_plugin::read_rig_config(io::TableReader::of(chosen->settings));
  } catch (const io::ConfigError& e) {
    throw CLI::ValidationError("--config", e.what());
  }
}

std::vector<WorkingPoint> working_points(const std::vector<std::string>& texts, const sim::RigConfig& rig) {
  std::vector<WorkingPoint> points;
  if (texts.empty()) {
    for (const auto& row : control::kTableA3) points.push_back({row.position_m(), static_cast<double>(row.load_kg)});
    return points;
  }
  const double stroke = rig.cylinder.geometry.stroke_m;
  for (const std::string& text : texts) {
    const std::optional<WorkingPoint> p = parse_working_point(text);
    if (!p || !(p->position_m >= 0.0 && p->position_m <= stroke) || !(p->load_kg >= 0.0)) {
      throw CLI::ValidationError("--points", "expected <position_m>:<load_kg> with the position in [0, " +
                                                 control::format_setting(stroke) + "] m and the load >= 0 kg, got '" +
                                                 text + "'");
    }
    points.push_back(*p);
  }
  return points;
}

std::vector<sim::CalibrationRow> calibrate(const sim::RigConfig& rig, const std::vector<WorkingPoint>& points) {
  const sim::Cylinder cylinder(rig.cylinder, rig.supply);
  // Table A3 identified the paper's rig: another cylinder or supply is not compared with it.
  const bool papers_rig = rig.cylinder == sim::CylinderParameters{} && rig.supply == sim::SupplyParameters{};
  std::vector<sim::CalibrationRow> rows;
  for (const WorkingPoint& p : points) {
    const auto identified =
        papers_rig ? control::find_identified_plant(p.position_m, p.load_kg) : std::nullopt;
    try {
      rows.push_back(sim::calibration_row(cylinder, p.position_m, p.load_kg,
                                          identified ? identified->b0 : kNotIdentified,
                                          identified ? identified->b1 : kNotIdentified,
                                          identified ? identified->k01 : kNotIdentified));
    } catch (const std::exception& e) {  // a rig with no oscillatory plant there
      throw CLI::ValidationError("calibration", "at " + control::format_setting(p.position_m) + " m, " +
                                                    control::format_setting(p.load_kg) + " kg: " + e.what());
    }
  }
  return rows;
}

void print_table(const std::vector<sim::CalibrationRow>& rows) {
  std::printf("%8s %6s | %8s %8s %6s | %6s %6s %5s | %6s %6s %6s\n", "pos[mm]", "load", "b0", "b0_tab",
              "dev%", "b1", "b1_tab", "dev%", "k01", "k01_tab", "dev%");
  std::vector<sim::CalibrationRow> compared;
  for (const auto& r : rows) {
    if (std::isnan(r.b0_table)) {
      std::printf("%8.0f %6.1f | %8.0f %8s %6s | %6.1f %6s %5s | %6.1f %6s %6s\n", r.position_m * 1e3, r.load_kg,
                  r.b0, "-", "-", r.b1, "-", "-", r.k01, "-", "-");
      continue;
    }
    compared.push_back(r);
    std::printf("%8.0f %6.1f | %8.0f %8.0f %+6.2f | %6.1f %6.0f %+5.2f | %6.1f %6.0f %+6.2f\n",
                r.position_m * 1e3, r.load_kg, r.b0, r.b0_table, 100 * r.b0_deviation(), r.b1, r.b1_table,
                100 * r.b1_deviation(), r.k01, r.k01_table, 100 * r.k01_deviation());
  }
  if (compared.empty()) return;
  const sim::CalibrationSummary worst = sim::worst_deviation(compared);
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
      "calibration",
      "A simulated rig's small-signal plant (b0, b1, k01) at working points, beside Table A3 where the rig is the "
      "paper's and the table has the point (default: the papers' rig at Table A3's 33 points)");
  auto json = std::make_shared<bool>(false);
  auto config = std::make_shared<std::string>();
  auto driver = std::make_shared<std::string>();
  auto points = std::make_shared<std::vector<std::string>>();
  cmd->add_flag("--json", *json, "print a JSON list instead of a table");
  auto* config_option = cmd->add_option("--config", *config,
                                        "a hsad configuration: linearize the rig its sim driver's settings describe")
                            ->check(CLI::ExistingFile);
  cmd->add_option("--driver", *driver, "the sim driver of --config to take, when it has several")
      ->needs(config_option);
  cmd->add_option("--points", *points,
                  "working points <position_m>:<load_kg>, comma-separated, e.g. 0.05:0,0.15:3 "
                  "(default: Table A3's 33 points)")
      ->delimiter(',');
  cmd->callback([json, config, driver, points] {
    const sim::RigConfig rig = config->empty() ? sim::RigConfig{} : configured_rig(*config, *driver);
    const std::vector<sim::CalibrationRow> rows = calibrate(rig, working_points(*points, rig));
    if (*json) {
      print_json(rows);
    } else {
      print_table(rows);
    }
  });
}

}  // namespace hsa::analyze
