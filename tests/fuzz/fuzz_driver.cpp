// Runs a fuzz target without libFuzzer (fuzz_target.hpp): every seed, every file named on the
// command line, then --runs random mutations of the seeds (bit flips, byte changes, insertions,
// deletions, truncations, splices), from a fixed random seed so that a failure repeats.
//
//   fuzz_<name> [--runs N] [--write-seeds DIR] [FILE...]
//
// --write-seeds DIR writes the seeds as files seed-<i> into DIR (the corpus tools/fuzz starts
// libFuzzer from) and exits.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include "tests/fuzz/fuzz_target.hpp"

namespace {

std::string mutate(std::string input, const std::vector<std::string>& seeds, std::mt19937_64& rng) {
  const int steps = 1 + static_cast<int>(rng() % 4);
  for (int i = 0; i < steps; ++i) {
    const std::size_t at = input.empty() ? 0 : rng() % input.size();
    switch (rng() % 6) {
      case 0:
        if (!input.empty()) input[at] = static_cast<char>(input[at] ^ (1u << (rng() % 8)));
        break;
      case 1:
        if (!input.empty()) input[at] = static_cast<char>(rng());
        break;
      case 2: input.insert(at, 1 + rng() % 8, static_cast<char>(rng())); break;
      case 3:
        if (!input.empty()) input.erase(at, 1 + rng() % 8);
        break;
      case 4: input.resize(at); break;
      case 5: {
        const std::string& other = seeds[rng() % seeds.size()];
        const std::size_t from = other.empty() ? 0 : rng() % other.size();
        input.insert(at, other, from, 1 + rng() % 32);
        break;
      }
    }
  }
  return input;
}

int run(const std::string& input) {
  return LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(input.data()), input.size());
}

}  // namespace

int main(int argc, char** argv) {
  long runs = 20000;
  std::vector<std::string> inputs = hsa_fuzz_seeds();
  const std::size_t seed_count = inputs.size();
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      runs = std::strtol(argv[++i], nullptr, 10);
    } else if (std::strcmp(argv[i], "--write-seeds") == 0 && i + 1 < argc) {
      const std::filesystem::path dir = argv[++i];
      std::filesystem::create_directories(dir);
      for (std::size_t k = 0; k < seed_count; ++k) {
        std::ofstream(dir / ("seed-" + std::to_string(k)), std::ios::binary) << inputs[k];
      }
      std::printf("%zu seeds written to %s\n", seed_count, dir.c_str());
      return 0;
    } else {
      std::ifstream f(argv[i], std::ios::binary);
      if (!f) {
        std::fprintf(stderr, "cannot read %s\n", argv[i]);
        return 2;
      }
      inputs.emplace_back(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
  }
  if (inputs.empty()) {
    std::fprintf(stderr, "no seeds and no files\n");
    return 2;
  }
  for (const std::string& input : inputs) run(input);
  std::mt19937_64 rng(20261124);
  for (long r = 0; r < runs; ++r) run(mutate(inputs[rng() % inputs.size()], inputs, rng));
  std::printf("%zu inputs and %ld mutations: no invariant broken\n", inputs.size(), runs);
  return 0;
}
