// The configuration loader (daemon/config/load_config.hpp) on any text. A text is either a
// configuration or an io::ConfigError that names the file; nothing else may come out (another exception,
// a crash, a hang). A configuration it accepts keeps the bounds docs/operation.md states for what matters
// most: at least one axis, a closed safe valve command, positive finite gains, soft limits in order.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "daemon/config/config_bounds.hpp"
#include "drivers/config_error.hpp"
#include "daemon/config/load_config.hpp"
#include "tests/fuzz/fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hsa::daemon;
  using bounds::kMaxSafeCommandBand;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const DaemonConfig c = parse_config(text, "fuzz.toml");
    HSA_FUZZ_CHECK(!c.axes.empty());
    for (const AxisConfig& a : c.axes) {
      HSA_FUZZ_CHECK(a.law != nullptr);
      const hsa::control::RuntimeGains g = a.law->gains();
      HSA_FUZZ_CHECK(std::isfinite(g.kp) && g.kp > 0.0);
      HSA_FUZZ_CHECK(std::isfinite(g.ki) && g.ki >= 0.0);
      HSA_FUZZ_CHECK(std::isfinite(a.law->max_speed_m_s()) && a.law->max_speed_m_s() > 0.0);
      HSA_FUZZ_CHECK(a.law->safe_command_refusal(a.safety.safe_valve_command, kMaxSafeCommandBand).empty());
      HSA_FUZZ_CHECK(a.limits.min_m < a.limits.max_m);
    }
  } catch (const hsa::io::ConfigError& e) {
    HSA_FUZZ_CHECK(std::string_view(e.what()).substr(0, 9) == "fuzz.toml");
  }
  return 0;
}

std::vector<std::string> hsa_fuzz_seeds() {
  std::vector<std::string> seeds;
  for (const auto& entry : std::filesystem::directory_iterator(HSA_SOURCE_DIR "/systemd")) {
    if (entry.path().extension() != ".toml") continue;
    std::ifstream f(entry.path(), std::ios::binary);
    seeds.emplace_back(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  return seeds;
}
