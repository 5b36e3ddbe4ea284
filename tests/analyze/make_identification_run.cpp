// Writes a closed-loop identification run of the simulated rig (identification_run.hpp) as the CSV
// `hsactl record` writes, for the command-line tests of `hsa-analyze identify`:
//   make_identification_run OUT.csv POSITION_M LOAD_KG SEED DURATION_S
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "tests/analyze/identification_run.hpp"

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s OUT.csv POSITION_M LOAD_KG SEED DURATION_S\n", argv[0]);
    return 2;
  }
  hsa::test::ExcitationRun run{.position_m = std::atof(argv[2]), .load_kg = std::atof(argv[3]),
                               .duration_s = std::atof(argv[5])};
  run.excitation.seed = std::strtoull(argv[4], nullptr, 10);
  std::ofstream out(argv[1]);
  out << hsa::test::excitation_csv(hsa::sim::RigConfig{}, run);
  return out ? 0 : 1;
}
