#include "control/plant_table.hpp"

#include <cmath>

namespace hsa::control {

std::optional<IdentifiedPlant> find_identified_plant(double position_m, double load_kg) {
  for (const IdentifiedPlant& row : kTableA3) {
    if (std::abs(row.position_m() - position_m) <= 1e-6 && std::abs(row.load_kg - load_kg) <= 1e-6)
      return row;
  }
  return std::nullopt;
}

}  // namespace hsa::control
