// The plant-set file's reader (plant_set/plant_set_file.hpp) on any text. A text is either refused
// with an io::ConfigError that names the file, or gives a set the writer writes back and the
// reader reads again to the same set: the bounds of the reader and the writer agree, and every
// plant it accepts has a positive, finite transfer function.
#include <cmath>
#include <sstream>
#include <string_view>

#include "drivers/config_error.hpp"
#include "plant_set/plant_set_file.hpp"
#include "tests/fuzz/fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  hsa::control::PlantSet set;
  try {
    set = hsa::plant_set::parse_plant_set(text, "fuzz.toml");
  } catch (const hsa::io::ConfigError& e) {
    HSA_FUZZ_CHECK(std::string_view(e.what()).substr(0, 9) == "fuzz.toml");
    return 0;
  }
  HSA_FUZZ_CHECK(!set.plants.empty() && set.nominal < set.plants.size());
  for (const auto& p : set.plants) {
    const auto plant = p.plant();
    HSA_FUZZ_CHECK(std::isfinite(plant.gain) && plant.gain > 0.0 && plant.b0 > 0.0 && plant.b1 > 0.0);
  }
  std::ostringstream out;
  try {
    hsa::plant_set::write_plant_set(out, set);
  } catch (const std::invalid_argument&) {
    // A name with a control character TOML escaped: the writer refuses what it cannot write.
    return 0;
  }
  const hsa::control::PlantSet again = hsa::plant_set::parse_plant_set(out.str(), "again.toml");
  HSA_FUZZ_CHECK(again.plants.size() == set.plants.size() && again.nominal == set.nominal);
  for (std::size_t i = 0; i < set.plants.size(); ++i) {
    HSA_FUZZ_CHECK(again.plants[i].name == set.plants[i].name);
    HSA_FUZZ_CHECK(again.plants[i].b0_per_s2.value == set.plants[i].b0_per_s2.value);
    HSA_FUZZ_CHECK(again.plants[i].k01_m_s.value == set.plants[i].k01_m_s.value);
  }
  HSA_FUZZ_CHECK(again.capability.extend.speed_limit_m_s == set.capability.extend.speed_limit_m_s);
  return 0;
}

std::vector<std::string> hsa_fuzz_seeds() {
  const std::string plant =
      "[[plant]]\nname = \"run.csv@3kg\"\nposition_m = 0.15\nload_kg = 3\nb0_per_s2 = 9616\nb0_per_s2_std = 60\n"
      "b1_per_s = 98.9\nb1_per_s_std = 0.8\nk01_m_s = 0.2244\nk01_m_s_std = 0.001\nk01_retracting_m_s = 0.2062\n"
      "k01_retracting_m_s_std = 0.002\ndelay_s = 0.00055\nkp_per_m = 200\nfit_index = 0.948\nnominal_score = 2.82\n";
  const std::string direction =
      "max_speed_m_s = 0.17\nmax_acceleration_m_s2 = 10.2\nspeed_limit_m_s = 0.119\nacceleration_limit_m_s2 = 7.1\n"
      "speed_pump_limited = true\nacceleration_force_limited = false\nworst_run = \"run.csv@3kg\"\nload_kg = 3\n";
  const std::string head =
      "format = \"hsa-plant-set\"\nversion = 1\nnominal = 0\nsupply_pressure_pa = 2500000\n"
      "pump_flow_m3_per_s = 8.333e-5\npiston_area_m2 = 4.9e-4\narea_ratio = 0.77\n[capability]\nmargin = 0.7\n"
      "[capability.extend]\n" + direction + "[capability.retract]\n" + direction;
  return {"", head + plant, head + plant + plant, head + plant + "[[plant]]\nname = \"\\u0001\"\n"};
}
