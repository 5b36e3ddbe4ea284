// The control laws an axis can be configured with, by name (`drive` of an axis).
//
// Each law lives in its own folder under control/laws/ and registers in law_registry.cpp with one
// line. A law class provides its name (kName), the axis-level tables it reads (kTables) and
// from_settings(), which reads them and builds it. The
// configuration loader asks this registry and knows no law itself.
#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "control/control_law.hpp"
#include "control/law_settings.hpp"
#include "control/laws/pi_cascade_law.hpp"

namespace hsa::control {

struct LawRegistration {
  std::string_view name;
  // The axis-level keys (tables) the law reads, so the loader can accept them for this law and
  // refuse them, naming the law, for another.
  std::span<const std::string_view> tables;
  // Reads the law's settings from the axis table and builds it; throws the reader's error, or
  // std::invalid_argument for parameters the law refuses as a whole.
  std::unique_ptr<ControlLaw> (*from_settings)(const LawSettings& axis, const LawTiming& timing);
};

// Every registered law, in registration order.
std::span<const LawRegistration> registered_laws();

// The law called `name`, or nullptr.
const LawRegistration* find_law(std::string_view name);

}  // namespace hsa::control
