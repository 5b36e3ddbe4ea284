// Test builds only (object library hsa_rt_counters): the replaceable global operator new/delete
// family, counting calls made while the RT-cycle flag is set, so a test can assert the steady-state
// cycle never touches the heap. Every replaceable signature is defined, because a
// missing one (say the aligned nothrow form) would silently bypass the count. Storage comes from
// malloc/posix_memalign and goes back through free, so all forms pair with each other.
//
// Outside the RT cycle the only cost is one thread-local read per call.
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>

#include "daemon/rt/rt_counters.hpp"
#include "daemon/rt/rt_cycle_flag.hpp"

namespace hsa::daemon {
namespace {

std::atomic<std::uint64_t> g_allocations{0};
std::atomic<std::uint64_t> g_deallocations{0};

void count_allocation() noexcept {
  if (t_in_rt_cycle) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
}

void count_deallocation(void* p) noexcept {
  if (p != nullptr && t_in_rt_cycle) {
    g_deallocations.fetch_add(1, std::memory_order_relaxed);
  }
}

void* try_allocate(std::size_t size) noexcept { return std::malloc(size == 0 ? 1 : size); }

void* try_allocate(std::size_t size, std::align_val_t alignment) noexcept {
  std::size_t align = static_cast<std::size_t>(alignment);
  if (align < sizeof(void*)) {
    align = sizeof(void*);  // posix_memalign's minimum
  }
  void* p = nullptr;
  return posix_memalign(&p, align, size == 0 ? 1 : size) == 0 ? p : nullptr;
}

// The standard's loop for the throwing forms: retry through the new-handler until it gives up.
template <typename... Align>
void* allocate_or_throw(std::size_t size, Align... alignment) {
  count_allocation();
  for (;;) {
    if (void* p = try_allocate(size, alignment...)) {
      return p;
    }
    std::new_handler handler = std::get_new_handler();
    if (handler == nullptr) {
      throw std::bad_alloc();
    }
    handler();
  }
}

template <typename... Align>
void* allocate_nothrow(std::size_t size, Align... alignment) noexcept {
  try {
    return allocate_or_throw(size, alignment...);
  } catch (...) {
    return nullptr;
  }
}

void release(void* p) noexcept {
  count_deallocation(p);
  std::free(p);
}

}  // namespace

std::uint64_t rt_allocations() noexcept { return g_allocations.load(std::memory_order_relaxed); }
std::uint64_t rt_deallocations() noexcept { return g_deallocations.load(std::memory_order_relaxed); }
bool rt_counters_linked() noexcept { return true; }

}  // namespace hsa::daemon

using hsa::daemon::allocate_nothrow;
using hsa::daemon::allocate_or_throw;
using hsa::daemon::release;

void* operator new(std::size_t size) { return allocate_or_throw(size); }
void* operator new[](std::size_t size) { return allocate_or_throw(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return allocate_nothrow(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return allocate_nothrow(size); }
void* operator new(std::size_t size, std::align_val_t al) { return allocate_or_throw(size, al); }
void* operator new[](std::size_t size, std::align_val_t al) { return allocate_or_throw(size, al); }
void* operator new(std::size_t size, std::align_val_t al, const std::nothrow_t&) noexcept {
  return allocate_nothrow(size, al);
}
void* operator new[](std::size_t size, std::align_val_t al, const std::nothrow_t&) noexcept {
  return allocate_nothrow(size, al);
}

void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
