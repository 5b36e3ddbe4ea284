// What a control law reads its configuration through.
//
// control/ knows no file format: the daemon implements this over its configuration reader
// (daemon/config/law_settings_reader.hpp), so a law's errors carry the file, line, column and key
// path like every other configuration error, and a law is configured from its own code without the
// configuration loader knowing its keys. Every getter throws the reader's error (a ConfigError in
// hsad) for a value outside its range, a wrong type, or a required key that is missing.
#pragma once

#include <array>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "control/gain_gate.hpp"
#include "control/setting_range.hpp"

namespace hsa::control {

class LawSettings {
 public:
  virtual ~LawSettings() = default;

  [[nodiscard]] virtual bool has(std::string_view key) const = 0;
  // The key as messages name it, with the table's path: "axes[0].pi.kp".
  [[nodiscard]] virtual std::string key_path(std::string_view key) const = 0;
  // `fallback` when the key is absent; without one the key is required.
  [[nodiscard]] virtual double number(std::string_view key, const SettingRange& range,
                                      std::optional<double> fallback = std::nullopt) const = 0;
  // true or false; `fallback` when the key is absent, without one the key is required.
  [[nodiscard]] virtual bool boolean(std::string_view key, std::optional<bool> fallback = std::nullopt) const = 0;
  // The string `key`; nullopt when it is absent. A value that is not a string fails with
  // "expected <expected>".
  [[nodiscard]] virtual std::optional<std::string> text(std::string_view key, std::string_view expected) const = 0;
  // An array of exactly `values.size()` numbers in `range`, read into `values`; left as it is when
  // the key is absent.
  virtual void numbers(std::string_view key, const SettingRange& range, double* values, std::size_t count) const = 0;
  // The sub-table `key`; nullptr when it is absent and not `required`. A missing required table
  // fails with "required key is missing, expected <what>".
  [[nodiscard]] virtual std::unique_ptr<LawSettings> table(std::string_view key, bool required,
                                                           std::string_view what) const = 0;
  virtual void reject_unknown_keys(std::initializer_list<std::string_view> known) const = 0;
  // Refuses the key's value: "<where>: <key path>: expected <expected>, got <value>".
  [[noreturn]] virtual void fail(std::string_view key, const std::string& expected) const = 0;
  // The plant-set file (docs/plant-set.md) the string `key` names, as the gain gate judges it;
  // nullopt when the key is absent. The daemon reads the file (control/ reads none): a relative
  // path is taken from the configuration file's folder, and a file that cannot be read or is not
  // a plant set fails naming the key, with the set's own file, line and key.
  [[nodiscard]] virtual std::optional<GatePlantSet> plant_set(std::string_view key) const = 0;
};

}  // namespace hsa::control
