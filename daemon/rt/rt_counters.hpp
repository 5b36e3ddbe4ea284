#pragma once

#include <cstdint>

namespace hsa::daemon {

// Process-wide counts of what threads did while their RT-cycle flag was set (rt_cycle_flag.hpp).
//
// hsa_daemon_rt defines all three as weak functions returning 0, so a production hsad links and
// reports zeros without paying for counting. Test builds link the object library hsa_rt_counters
// (daemon/rt/CMakeLists.txt) directly into the executable: its strong definitions replace the weak
// ones, it replaces the global operator new/delete family (allocations, deallocations), and it
// interposes pthread_mutex_lock/trylock/timedlock/clocklock and the pthread_rwlock_*lock family
// (lock acquisitions, forwarded to glibc through dlsym(RTLD_NEXT)).
//
// Not counted: direct malloc/free calls from C code, and locks glibc takes internally (those never
// go through the public symbols). std::mutex, std::shared_mutex and std::condition_variable's mutex
// are counted.
[[nodiscard]] std::uint64_t rt_allocations() noexcept;
[[nodiscard]] std::uint64_t rt_deallocations() noexcept;
[[nodiscard]] std::uint64_t rt_lock_acquisitions() noexcept;

// True when the counters above are real (hsa_rt_counters is linked), false for the weak defaults.
[[nodiscard]] bool rt_counters_linked() noexcept;

}  // namespace hsa::daemon
