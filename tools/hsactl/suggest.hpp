// "Did you mean ...?" for a mistyped command: the nearest name by edit distance.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace hsa::ctl {

// Levenshtein distance: insertions, deletions and substitutions, each 1.
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate nearest to `word`, when it is near enough to be what was meant: at most 2 edits,
// and fewer than half of the word's letters (so "xy" suggests nothing).
std::optional<std::string> nearest(std::string_view word, std::span<const std::string> candidates);

// What to say of a word that is none of `commands`: "unknown command 'stauts'; did you mean
// 'status'?", without the question when no command is near.
std::string unknown_command(std::string_view word, std::span<const std::string> commands);

}  // namespace hsa::ctl
