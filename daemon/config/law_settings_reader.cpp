#include "daemon/config/law_settings_reader.hpp"

#include <filesystem>
#include <memory>
#include <string>

#include <toml++/toml.h>

#include "control/gain_gate.hpp"
#include "plant_set/plant_set_file.hpp"

namespace hsa::daemon {

double LawSettingsReader::number(std::string_view key, const control::SettingRange& range,
                                 std::optional<double> fallback) const {
  return table_.number(key, range, fallback);
}

void LawSettingsReader::numbers(std::string_view key, const control::SettingRange& range, double* values,
                                std::size_t count) const {
  const toml::node* node = table_.table().get(key);
  if (node == nullptr) return;
  const control::SettingRange& r = range;
  // "a finite number in (0, 1]" → "an array of 4 numbers in (0, 1]"
  std::string each = r.expected();
  const std::string prefix = "a finite number";
  if (each.rfind(prefix, 0) == 0) each = each.substr(prefix.size());
  const std::string expected = "an array of " + std::to_string(count) + " numbers" + each;
  const toml::array* array = node->as_array();
  if (array == nullptr || array->size() != count) table_.fail(key, expected);
  for (std::size_t i = 0; i < count; ++i) {
    const std::optional<double> v = array->get(i)->value<double>();
    if (!v || !r.contains(*v)) table_.fail(key, expected);
    values[i] = *v;
  }
}

std::optional<std::string> LawSettingsReader::text(std::string_view key, std::string_view expected) const {
  if (!table_.has(key)) return std::nullopt;
  return table_.string(key, expected);
}

std::unique_ptr<control::LawSettings> LawSettingsReader::table(std::string_view key, bool required,
                                                               std::string_view what) const {
  std::optional<io::TableReader> t = table_.table(key, required, what);
  if (!t) return nullptr;
  return std::unique_ptr<control::LawSettings>(new LawSettingsReader(std::move(*t), loaded_));
}

std::optional<control::GatePlantSet> LawSettingsReader::plant_set(std::string_view key) const {
  if (!table_.has(key)) return std::nullopt;
  std::filesystem::path path = table_.string(key, "the path of a plant-set file (hsa-analyze identify --set)");
  const std::shared_ptr<const std::string>& configuration = table_.table().get(key)->source().path;
  if (path.is_relative() && configuration) path = std::filesystem::path(*configuration).parent_path() / path;
  try {
    control::PlantSet set = plant_set::load_plant_set(path.string());
    control::GatePlantSet gate = control::gate_plant_set(set, path.string());
    *loaded_ = LoadedPlantSet{path.string(), std::move(set)};
    return gate;
  } catch (const std::exception& e) {
    table_.fail(key, std::string("a plant-set file hsa can read (") + e.what() + ")");
  }
}

}  // namespace hsa::daemon
