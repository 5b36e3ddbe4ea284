// A plant set (control/plant_set.hpp) from closed-loop runs at several working points: each run
// identified alone (identify_run.hpp), the nominal plant chosen over all of them by eq 49 of
// Puglisi et al. (2015) (nominal_plant.hpp), and the axis's capability at the worst load among
// them (axis_capability.hpp). Pure: the caller reads the files and names the working points.
#pragma once

#include <string>
#include <vector>

#include "control/identification/axis_capability.hpp"
#include "control/identification/identify_run.hpp"
#include "control/identification/nominal_plant.hpp"
#include "control/plant_set.hpp"

namespace hsa::control::identification {

struct NamedRun {
  std::string name;      // as the plant will be named in the set
  double load_kg = 0.0;  // the external load the operator put on the rod
  ClosedLoopRun run;
};

struct SetIdentification {
  std::vector<Identification> each;       // one per run, in order
  std::vector<AxisCapability> capability;  // one per run
  NominalChoice nominal;
  PlantSet set;
};

// Throws RunRefused (naming the run) when a run cannot be identified, std::invalid_argument for
// no run, two runs with the same name, or a rating axis_capability refuses.
[[nodiscard]] SetIdentification identify_set(const std::vector<NamedRun>& runs, const IdentifyOptions& options,
                                             const SupplyRating& rating);

// The set entry of one identified run.
[[nodiscard]] PlantSetEntry set_entry(const std::string& name, double load_kg, const Identification& id);

}  // namespace hsa::control::identification
