// The contract between a fuzz target and what runs it.
//
// Each fuzz_<name>.cpp defines LLVMFuzzerTestOneInput (libFuzzer's entry point: one input, any
// bytes; it aborts on a broken invariant, and returns 0 otherwise) and hsa_fuzz_seeds() (valid
// inputs to start from). Two programs run a target:
//   - built with clang -fsanitize=fuzzer,address,undefined (tools/fuzz), libFuzzer explores
//     inputs guided by coverage, starting from the seeds that tools/fuzz writes to a corpus;
//   - in every build, fuzz_driver.cpp makes it a test: every seed, then a fixed number of seeded
//     random mutations of them (a short, reproducible run; ctest label "fuzz").
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// Valid inputs for the target, built in code so they follow the types they exercise.
std::vector<std::string> hsa_fuzz_seeds();

// A broken invariant: says which and aborts, so every fuzzer and sanitizer reports the input.
#define HSA_FUZZ_CHECK(condition)                                                          \
  do {                                                                                     \
    if (!(condition)) {                                                                    \
      std::fprintf(stderr, "fuzz invariant broken: %s (%s:%d)\n", #condition, __FILE__, __LINE__); \
      std::abort();                                                                        \
    }                                                                                      \
  } while (0)
