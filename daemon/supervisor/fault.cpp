#include "daemon/supervisor/fault.hpp"

#include <cstdio>

namespace hsa::daemon {
namespace {

struct FaultText {
  std::string_view name;
  std::string_view summary;
  const char* detail;
  double scale;
};

constexpr std::array<FaultText, kFaultReasonCount> kFaultTexts{{
    {"none", "no fault", "", 1.0},
#define HSA_FAULT_TEXT(reason, wire, kind, summary, detail, scale) {#reason, summary, detail, scale},
    HSA_FAULT_REASONS(HSA_FAULT_TEXT)
#undef HSA_FAULT_TEXT
}};

const FaultText* text_of(FaultReason reason) noexcept {
  const auto i = static_cast<std::size_t>(reason);
  return i < kFaultTexts.size() ? &kFaultTexts[i] : nullptr;
}

}  // namespace

std::string_view to_string(FaultReason reason) noexcept {
  const FaultText* t = text_of(reason);
  return t != nullptr ? t->name : "?";
}

std::string_view summary(FaultReason reason) noexcept {
  const FaultText* t = text_of(reason);
  return t != nullptr ? t->summary : "?";
}

std::string_view to_string(FaultSignal signal) noexcept {
  if (signal == FaultSignal::none) return "";
  const auto i = static_cast<std::size_t>(signal) - 1;
  return i < kAxisInputCount ? kAxisInputs[i].name : "?";
}

std::string describe(const FaultRecord& r) {
  char text[160];
  const std::string signal(to_string(r.signal));
  // The classes whose sentence depends on more than a value and a limit.
  switch (r.reason) {
    case FaultReason::estop:
      if (r.status != io::SampleStatus::ok) {
        std::snprintf(text, sizeof text, "e-stop input %s", std::string(io::to_string(r.status)).c_str());
        return text;
      }
      return "e-stop pressed";
    case FaultReason::sensor_not_ok:
      if (r.status == io::SampleStatus::stale && r.limit > 0.0) {
        std::snprintf(text, sizeof text, "%s stale: no new sample for %.1f ms (limit %.1f ms)",
                      signal.c_str(), r.value * 1e3, r.limit * 1e3);
        return text;
      }
      std::snprintf(text, sizeof text, "%s sample %s", signal.c_str(),
                    std::string(io::to_string(r.status)).c_str());
      return text;
    case FaultReason::inputs_not_ready:
      // The input's status says only that nothing came (disconnected): why is its driver's to
      // say (a refused connection, a silent device, an exception answer), which the operator
      // thread adds.
      std::snprintf(text, sizeof text, "no first sample from %s within %.1f s of start-up", signal.c_str(),
                    r.limit);
      return text;
    default: break;
  }
  const FaultText* t = text_of(r.reason);
  if (t == nullptr) return "?";
  const std::string_view detail(t->detail);
  if (detail.empty()) return std::string(t->summary);
  if (detail.starts_with("%s")) {
    std::snprintf(text, sizeof text, t->detail, signal.c_str(), r.value * t->scale, r.limit * t->scale);
  } else {
    std::snprintf(text, sizeof text, t->detail, r.value * t->scale, r.limit * t->scale);
  }
  return text;
}

}  // namespace hsa::daemon
