// control::LawSettings over the configuration's io::TableReader: a control law reads its own tables
// of an axis, and its errors carry the file, line, column and key path of every other
// configuration error.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "control/law_settings.hpp"
#include "control/plant_set.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

// A plant-set file a law read through plant_set(), as read: the configuration checks the axis's
// motion bounds against its capability afterwards (capability_check.hpp), on the same file the gain
// gate judged, read once.
struct LoadedPlantSet {
  std::string path;  // resolved against the configuration's folder, as messages name it
  control::PlantSet set;
};

class LawSettingsReader final : public control::LawSettings {
 public:
  explicit LawSettingsReader(io::TableReader table)
      : table_(std::move(table)), loaded_(std::make_shared<std::optional<LoadedPlantSet>>()) {}

  // The plant set the law read through this reader or the tables it opened (a law reads one, the
  // axis's); nullopt when it read none.
  [[nodiscard]] const std::optional<LoadedPlantSet>& loaded_plant_set() const { return *loaded_; }

  [[nodiscard]] bool has(std::string_view key) const override { return table_.has(key); }
  [[nodiscard]] std::string key_path(std::string_view key) const override { return table_.key_path(key); }
  [[nodiscard]] double number(std::string_view key, const control::SettingRange& range,
                              std::optional<double> fallback) const override;
  void numbers(std::string_view key, const control::SettingRange& range, double* values,
               std::size_t count) const override;
  [[nodiscard]] bool boolean(std::string_view key, std::optional<bool> fallback) const override {
    return table_.boolean(key, fallback);
  }
  [[nodiscard]] std::unique_ptr<control::LawSettings> table(std::string_view key, bool required,
                                                            std::string_view what) const override;
  void reject_unknown_keys(std::initializer_list<std::string_view> known) const override {
    table_.reject_unknown_keys(known);
  }
  [[noreturn]] void fail(std::string_view key, const std::string& expected) const override {
    table_.fail(key, expected);
  }
  [[nodiscard]] std::optional<std::string> text(std::string_view key, std::string_view expected) const override;
  [[nodiscard]] std::optional<control::GatePlantSet> plant_set(std::string_view key) const override;

 private:
  LawSettingsReader(io::TableReader table, std::shared_ptr<std::optional<LoadedPlantSet>> loaded)
      : table_(std::move(table)), loaded_(std::move(loaded)) {}

  io::TableReader table_;
  std::shared_ptr<std::optional<LoadedPlantSet>> loaded_;  // shared with the tables opened from it
};

}  // namespace hsa::daemon
