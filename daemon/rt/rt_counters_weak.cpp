// Weak defaults of the RT counters (see rt_counters.hpp): a production build that does not link
// hsa_rt_counters counts nothing and says so through rt_counters_linked().
#include "daemon/rt/rt_counters.hpp"

namespace hsa::daemon {

[[gnu::weak]] std::uint64_t rt_allocations() noexcept { return 0; }
[[gnu::weak]] std::uint64_t rt_deallocations() noexcept { return 0; }
[[gnu::weak]] std::uint64_t rt_lock_acquisitions() noexcept { return 0; }
[[gnu::weak]] bool rt_counters_linked() noexcept { return false; }

}  // namespace hsa::daemon
