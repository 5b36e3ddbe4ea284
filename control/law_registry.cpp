#include "control/law_registry.hpp"

#include <array>

#include "control/laws/direct_servo/direct_servo_law.hpp"
#include "control/laws/proportional_cascade/proportional_cascade_law.hpp"

namespace hsa::control {

namespace {

template <class Law>
constexpr LawRegistration registration() {
  return {Law::kName, Law::kTables, &Law::from_settings};
}

// One line per law.
constexpr std::array kLaws{
    registration<DirectServoLaw>(),
    registration<ProportionalCascadeLaw>(),
};

}  // namespace

std::span<const LawRegistration> registered_laws() { return kLaws; }

const LawRegistration* find_law(std::string_view name) {
  for (const LawRegistration& law : kLaws) {
    if (law.name == name) return &law;
  }
  return nullptr;
}

}  // namespace hsa::control
