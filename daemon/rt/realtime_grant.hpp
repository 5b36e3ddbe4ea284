#pragma once

#include <string>

namespace hsa::daemon {

// What the kernel granted the RT thread at start, for status and the warn-once
// message. detail is one human-readable line: what was granted, and for each refusal what was
// asked, the errno text and what would fix it.
struct RealtimeGrant {
  bool sched_fifo = false;
  bool memory_locked = false;
  bool affinity = false;  // pinned to RtConfig::cpu; false when no CPU was asked for
  std::string detail;
};

}  // namespace hsa::daemon
