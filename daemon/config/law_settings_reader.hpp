// control::LawSettings over the configuration's io::TableReader: a control law reads its own tables
// of an axis, and its errors carry the file, line, column and key path of every other
// configuration error.
#pragma once

#include "control/law_settings.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

class LawSettingsReader final : public control::LawSettings {
 public:
  explicit LawSettingsReader(io::TableReader table) : table_(std::move(table)) {}

  [[nodiscard]] bool has(std::string_view key) const override { return table_.has(key); }
  [[nodiscard]] std::string key_path(std::string_view key) const override { return table_.key_path(key); }
  [[nodiscard]] double number(std::string_view key, const control::SettingRange& range,
                              std::optional<double> fallback) const override;
  void numbers(std::string_view key, const control::SettingRange& range, double* values,
               std::size_t count) const override;
  [[nodiscard]] std::unique_ptr<control::LawSettings> table(std::string_view key, bool required,
                                                            std::string_view what) const override;
  void reject_unknown_keys(std::initializer_list<std::string_view> known) const override {
    table_.reject_unknown_keys(known);
  }
  [[noreturn]] void fail(std::string_view key, const std::string& expected) const override {
    table_.fail(key, expected);
  }
  [[nodiscard]] std::optional<control::GatePlantSet> plant_set(std::string_view key) const override;

 private:
  io::TableReader table_;
};

}  // namespace hsa::daemon
