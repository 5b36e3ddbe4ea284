// Seeds for the rig's independent noise sources, all derived from the one seed a test gives, so
// that adding a sensor does not shift the noise another sensor sees.
#pragma once

#include <cstdint>

namespace hsa::sim {

// SplitMix64 (Steele, Lea, Flood 2014): a well-mixed 64-bit value for each (seed, stream) pair.
[[nodiscard]] constexpr std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace hsa::sim
