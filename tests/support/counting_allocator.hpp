// Counts heap allocations made through operator new, for tests that check a real-time path
// allocates nothing. Linking the `hsa_test_counting_allocator` object library into a test
// executable replaces the global operator new/delete family there; plugins loaded at run time
// bind to the executable's operator new, so their allocations count too.
#pragma once

namespace hsa::test {

long process_allocations() noexcept;  // every thread
long thread_allocations() noexcept;   // the calling thread only (e.g. the RT loop, not a bus thread)

}  // namespace hsa::test
