// A forward declaration of toml++'s table, so that the headers the real-time path includes
// (driver.hpp, driver_handle.hpp) do not pull in the whole TOML parser.
//
// toml++ 3 puts its types in the inline namespace toml::v3. Should a later major version move
// them, this declaration and <toml++/toml.h> name two different classes and any file that
// includes both fails to compile: loudly, not silently.
#pragma once

namespace toml {
inline namespace v3 {
class table;
}  // namespace v3
}  // namespace toml
