// A bounded wait for another thread's progress, for the concurrency tests: at their checkpoints
// the writer waits until the reader has taken what it published, so the two threads provably
// overlap even when both are pinned to one loaded CPU. The deadline keeps a broken reader from
// hanging the test: the caller counts a missed checkpoint and fails on it.
#pragma once

#include <chrono>
#include <thread>

namespace hsa::test {

// Yields until `done()` holds or `timeout` passes; returns whether it held.
template <class Done>
bool yield_until(Done done, std::chrono::steady_clock::duration timeout = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::yield();
  }
  return true;
}

}  // namespace hsa::test
