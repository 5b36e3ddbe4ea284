#include "daemon/config/input_bounds.hpp"

#include <string>

#include "drivers/config_error.hpp"

namespace hsa::daemon {

void check_input_bounds(std::string_view text, std::string_view source_name) {
  const std::string source(source_name);
  if (text.size() > kMaxConfigBytes) {
    throw io::ConfigError(source + ": the configuration is " + std::to_string(text.size()) + " bytes, more than the " +
                      std::to_string(kMaxConfigBytes) + " hsad reads");
  }
  int line = 1;
  int depth = 0;
  int dots = 0;
  const auto fail = [&](const std::string& what) {
    throw io::ConfigError(source + ":" + std::to_string(line) + ": " + what + " deeper than " +
                      std::to_string(kMaxNesting) + " levels, more than any configuration needs");
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      dots = 0;
    } else if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {
      const bool multi_line = text.substr(i, 3) == std::string(3, c);
      const std::string_view end = multi_line ? text.substr(i, 3) : text.substr(i, 1);
      i += end.size();
      while (i < text.size() && text.substr(i, end.size()) != end) {
        if (text[i] == '\n') ++line;
        if (c == '"' && text[i] == '\\') ++i;  // an escape: the next character is not the end
        ++i;
      }
      i += end.size() - 1;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) fail("arrays, inline tables or table headers nested");
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    } else if (c == '.') {
      if (++dots >= kMaxNesting) fail("a dotted key");
    } else if (c == '=' || c == ',') {
      dots = 0;
    }
  }
}

}  // namespace hsa::daemon
