// The sim plugin's reader of the rig (drivers/sim/rig_settings.hpp) on any settings text. A text
// is either refused with an io::ConfigError that names the file, or gives a RigConfig the rig
// accepts as is: a sim::Rig built from it does not throw, and a few steps keep the rod finite and
// within its stroke. Bounds and consistency checks that miss a combination the model cannot take
// show here as a throwing constructor or a non-finite state.
#include <cmath>
#include <string_view>

#include <toml++/toml.h>

#include "drivers/config_error.hpp"
#include "drivers/sim/rig_settings.hpp"
#include "tests/fuzz/fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  toml::table table;
  try {
    table = toml::parse(text, std::string_view("fuzz.toml"));
  } catch (const toml::parse_error&) {
    return 0;  // not TOML: the daemon's reader refuses it before any plugin sees it
  }
  hsa::sim::RigConfig config;
  try {
    config = hsa::io::sim_plugin::read_rig_config(hsa::io::TableReader::of(table));
  } catch (const hsa::io::ConfigError& e) {
    HSA_FUZZ_CHECK(std::string_view(e.what()).substr(0, 9) == "fuzz.toml");
    return 0;
  }
  try {
    hsa::sim::Rig rig(config);
    rig.set_valve_command(config.valve == hsa::sim::ValveKind::servo ? 0.5 : 2.0);
    for (int i = 0; i < 20; ++i) rig.step();
    const double y = rig.cylinder_state().position_m;
    HSA_FUZZ_CHECK(std::isfinite(y) && y >= 0.0 && y <= config.cylinder.geometry.stroke_m);
  } catch (...) {
    const bool the_model_takes_what_the_reader_accepts = false;
    HSA_FUZZ_CHECK(the_model_takes_what_the_reader_accepts);
  }
  return 0;
}

std::vector<std::string> hsa_fuzz_seeds() {
  return {
      "",
      "valve = \"proportional\"\nload_kg = 6\n[rig.proportional_valve]\nhysteresis_width_a = 0.2\n"
      "[rig.lvdt]\nanti_aliasing_order = 2\n",
      "initial_position_m = 0.2\n[rig.cylinder]\nstroke_m = 0.4\nbore_m = 0.032\nrod_m = 0.016\n"
      "[rig.supply]\npump_flow_m3_per_s = 1.333e-4\n[rig.dynamics]\nbulk_modulus_pa = 1.2e9\n"
      "moving_mass_kg = 4\n[rig.servo_valve]\nbandwidth_hz = 100\n",
  };
}
