// "Did you mean": the name nearest a typo among those a file or a command line offers (a log's
// header, the commands of the CLI), by edit distance.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace extwrench {

/// Levenshtein distance (insertions, deletions, substitutions of bytes).
[[nodiscard]] std::size_t edit_distance(std::string_view a, std::string_view b);

/// The candidate nearest `word` when it is a near miss (fewer than `max_distance` edits, and not
/// `word` itself); "" otherwise. The first of equally near candidates.
[[nodiscard]] std::string nearest_name(std::string_view word,
                                       const std::vector<std::string>& candidates,
                                       std::size_t max_distance = 3);

}  // namespace extwrench
