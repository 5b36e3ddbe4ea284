// Test builds only (object library hsa_rt_counters): interposes the pthread lock-acquiring
// functions, counts calls made while the RT-cycle flag is set, and forwards to glibc's definitions
// found with dlsym(RTLD_NEXT) (the steady-state cycle takes no lock).
//
// Linked into the executable, these definitions win over libc's for the executable's own calls
// (std::mutex and std::shared_mutex call them from inline code) and, because the linker exports a
// definition that a shared library references, for calls from libstdc++ and other libraries too.
//
// The real functions are resolved into plain atomics, never through a function-local static: its
// guard may itself take a lock and recurse into these functions.
#include <dlfcn.h>
#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "daemon/rt/rt_counters.hpp"
#include "daemon/rt/rt_cycle_flag.hpp"

namespace hsa::daemon {
namespace {

std::atomic<std::uint64_t> g_locks{0};

void count_lock() noexcept {
  if (t_in_rt_cycle) {
    g_locks.fetch_add(1, std::memory_order_relaxed);
  }
}

// The next definition of `name` after this executable, i.e. glibc's. Racing resolutions agree, so a
// relaxed cache is enough.
template <typename Fn>
Fn real(std::atomic<Fn>& cache, const char* name) noexcept {
  Fn fn = cache.load(std::memory_order_relaxed);
  if (fn == nullptr) {
    fn = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
    if (fn == nullptr) {
      std::fprintf(stderr, "hsa_rt_counters: cannot find %s after this object\n", name);
      std::abort();
    }
    cache.store(fn, std::memory_order_relaxed);
  }
  return fn;
}

using MutexFn = int (*)(pthread_mutex_t*);
using MutexTimedFn = int (*)(pthread_mutex_t*, const struct timespec*);
using MutexClockFn = int (*)(pthread_mutex_t*, clockid_t, const struct timespec*);
using RwFn = int (*)(pthread_rwlock_t*);
using RwTimedFn = int (*)(pthread_rwlock_t*, const struct timespec*);
using RwClockFn = int (*)(pthread_rwlock_t*, clockid_t, const struct timespec*);

std::atomic<MutexFn> g_mutex_lock{nullptr};
std::atomic<MutexFn> g_mutex_trylock{nullptr};
std::atomic<MutexTimedFn> g_mutex_timedlock{nullptr};
std::atomic<MutexClockFn> g_mutex_clocklock{nullptr};
std::atomic<RwFn> g_rw_rdlock{nullptr};
std::atomic<RwFn> g_rw_wrlock{nullptr};
std::atomic<RwFn> g_rw_tryrdlock{nullptr};
std::atomic<RwFn> g_rw_trywrlock{nullptr};
std::atomic<RwTimedFn> g_rw_timedrdlock{nullptr};
std::atomic<RwTimedFn> g_rw_timedwrlock{nullptr};
std::atomic<RwClockFn> g_rw_clockrdlock{nullptr};
std::atomic<RwClockFn> g_rw_clockwrlock{nullptr};

// Resolve the two hot ones before main, while the process is still single-threaded.
[[gnu::constructor]] void resolve_early() {
  (void)real(g_mutex_lock, "pthread_mutex_lock");
  (void)real(g_mutex_trylock, "pthread_mutex_trylock");
}

}  // namespace

std::uint64_t rt_lock_acquisitions() noexcept { return g_locks.load(std::memory_order_relaxed); }

}  // namespace hsa::daemon

using namespace hsa::daemon;  // NOLINT: the definitions below must stay at global scope

extern "C" {

int pthread_mutex_lock(pthread_mutex_t* m) noexcept {
  count_lock();
  return real(g_mutex_lock, "pthread_mutex_lock")(m);
}
int pthread_mutex_trylock(pthread_mutex_t* m) noexcept {
  count_lock();
  return real(g_mutex_trylock, "pthread_mutex_trylock")(m);
}
int pthread_mutex_timedlock(pthread_mutex_t* m, const struct timespec* t) noexcept {
  count_lock();
  return real(g_mutex_timedlock, "pthread_mutex_timedlock")(m, t);
}
int pthread_mutex_clocklock(pthread_mutex_t* m, clockid_t c, const struct timespec* t) noexcept {
  count_lock();
  return real(g_mutex_clocklock, "pthread_mutex_clocklock")(m, c, t);
}
int pthread_rwlock_rdlock(pthread_rwlock_t* l) noexcept {
  count_lock();
  return real(g_rw_rdlock, "pthread_rwlock_rdlock")(l);
}
int pthread_rwlock_wrlock(pthread_rwlock_t* l) noexcept {
  count_lock();
  return real(g_rw_wrlock, "pthread_rwlock_wrlock")(l);
}
int pthread_rwlock_tryrdlock(pthread_rwlock_t* l) noexcept {
  count_lock();
  return real(g_rw_tryrdlock, "pthread_rwlock_tryrdlock")(l);
}
int pthread_rwlock_trywrlock(pthread_rwlock_t* l) noexcept {
  count_lock();
  return real(g_rw_trywrlock, "pthread_rwlock_trywrlock")(l);
}
int pthread_rwlock_timedrdlock(pthread_rwlock_t* l, const struct timespec* t) noexcept {
  count_lock();
  return real(g_rw_timedrdlock, "pthread_rwlock_timedrdlock")(l, t);
}
int pthread_rwlock_timedwrlock(pthread_rwlock_t* l, const struct timespec* t) noexcept {
  count_lock();
  return real(g_rw_timedwrlock, "pthread_rwlock_timedwrlock")(l, t);
}
int pthread_rwlock_clockrdlock(pthread_rwlock_t* l, clockid_t c, const struct timespec* t) noexcept {
  count_lock();
  return real(g_rw_clockrdlock, "pthread_rwlock_clockrdlock")(l, c, t);
}
int pthread_rwlock_clockwrlock(pthread_rwlock_t* l, clockid_t c, const struct timespec* t) noexcept {
  count_lock();
  return real(g_rw_clockwrlock, "pthread_rwlock_clockwrlock")(l, c, t);
}

}  // extern "C"
