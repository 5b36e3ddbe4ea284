#include "drivers/sample_status.hpp"

namespace hsa::io {

std::string_view to_string(SampleStatus status) {
  switch (status) {
    case SampleStatus::ok: return "ok";
    case SampleStatus::stale: return "stale";
    case SampleStatus::out_of_range: return "out of range";
    case SampleStatus::disconnected: return "disconnected";
  }
  return "unknown status";
}

}  // namespace hsa::io
