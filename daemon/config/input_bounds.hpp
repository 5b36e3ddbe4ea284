// Bounds on the configuration text, checked before the TOML parser sees it.
//
// toml++ parses nested arrays, inline tables and dotted keys recursively, so a file with a table
// header 50,000 keys deep ([a.a.a. ...]) overflows its stack and kills hsad. A real configuration
// is a few kilobytes with keys two or three deep, so the text is refused, with the file and the
// line, when it is larger than kMaxConfigBytes, nests arrays or inline tables deeper than
// kMaxNesting, or has a dotted key of more than kMaxNesting parts.
//
// Algorithm: one pass over the text that skips comments and strings (basic, literal and their
// multi-line forms, with escapes), counts the open '[' and '{', and counts the dots of the current
// key or value, which '=', ',' and the end of a line end. It does not validate TOML: the parser
// does that next, on text this pass has shown to be shallow enough to parse safely.
#pragma once

#include <cstddef>
#include <string_view>

namespace hsa::daemon {

inline constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;  // 1 MiB
inline constexpr int kMaxNesting = 32;

// Throws io::ConfigError ("<source>:<line>: ...") when `text` is out of bounds.
void check_input_bounds(std::string_view text, std::string_view source_name);

}  // namespace hsa::daemon
