#include "tools/hsa_analyze/valve_file.hpp"

#include <fstream>
#include <optional>
#include <sstream>

#include "drivers/config_error.hpp"
#include "drivers/sim/rig_settings.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::analyze {

sim::ProportionalValveParameters parse_valve_file(std::string_view text, std::string_view source_name) {
  const toml::table document = io::parse_toml(text, source_name);
  const io::TableReader root = io::TableReader::root(document, source_name);
  root.reject_unknown_keys({"rig"});
  if (const std::optional<io::TableReader> rig = root.table("rig", false, "a table [rig.proportional_valve]"))
    rig->reject_unknown_keys({"proportional_valve"});
  return io::sim_plugin::read_rig_config(root).proportional_valve;
}

sim::ProportionalValveParameters load_valve_file(const std::string& path) {
  std::ifstream file(path);
  if (!file.is_open()) throw io::ConfigError(path + ": cannot open the valve file");
  std::ostringstream text;
  text << file.rdbuf();
  return parse_valve_file(text.str(), path);
}

}  // namespace hsa::analyze
