// A shipped example configuration, edited for the real-kernel VM: read whole, changed by
// first-match regular-expression replacements, written where hsad in the VM reads it. A
// replacement that no longer matches fails the test: the example changed under the test.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>

namespace hsa::test {

class ExampleConfig {
 public:
  explicit ExampleConfig(const std::string& path) {
    std::ifstream f(path);
    std::stringstream s;
    s << f.rdbuf();
    text_ = s.str();
  }

  void replace(const std::regex& re, const std::string& with) {
    std::string next = std::regex_replace(text_, re, with, std::regex_constants::format_first_only);
    if (next == text_) ADD_FAILURE() << "the example configuration no longer matches " << with;
    text_ = std::move(next);
  }

  // Writes the edited text to `path`; returns `path`.
  std::string write(const std::string& path) const {
    std::ofstream(path) << text_;
    return path;
  }

 private:
  std::string text_;
};

}  // namespace hsa::test
