// The one exception configuration reading throws, in the daemon and in the plugins. Its message is
// ready for an operator, in the compiler-like form editors and terminals turn into links:
//   hsad.toml:14:7: axes[0].pi.kp: expected a finite number > 0, got -3
// (file, line and column, key path, what was expected and what was found).
#pragma once

#include <stdexcept>

namespace hsa::io {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hsa::io
