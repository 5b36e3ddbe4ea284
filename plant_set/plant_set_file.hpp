// The plant-set file: a TOML document with one [[plant]] per identified working point, the
// nominal plant's index and the axis's [capability] (control/plant_set.hpp holds it in memory;
// docs/plant-set.md is the format's description, key by key). The writer prints every number so
// that the reader gives it back exactly; the reader checks every key with io::TableReader, so an
// error names file:line:column, the key and what was expected, and refuses unknown keys.
#pragma once

#include <iosfwd>
#include <string>
#include <string_view>

#include "control/plant_set.hpp"

namespace hsa::plant_set {

inline constexpr std::string_view kFormatName = "hsa-plant-set";

// Throws io::ConfigError ("<source>:<line>:<column>: <key>: expected …, got …").
[[nodiscard]] control::PlantSet parse_plant_set(std::string_view text, std::string_view source_name);
// Reads the file; a file that cannot be read is an io::ConfigError naming it too.
[[nodiscard]] control::PlantSet load_plant_set(const std::string& path);

// Throws std::invalid_argument for a set the reader would refuse (no plant, a nominal out of
// range, a name with a character TOML cannot hold), so a file written is a file that reads.
void write_plant_set(std::ostream& out, const control::PlantSet& set);

}  // namespace hsa::plant_set
