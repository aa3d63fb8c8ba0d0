// The one rule for numbers written as text, shared by every format: CSV cells, YAML scalars,
// URDF attributes and command-line values. A number is the whole text read by std::from_chars
// ('.' decimal point, optional exponent, no hex, locale-independent) with an optional single
// leading '+', which other tools write. Each format states what else it accepts in NumberRules.
#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

namespace extwrench {

/// What a format accepts beyond a plain finite number.
struct NumberRules {
  bool trim_space = false;  ///< white space around the number is ignored (URDF, YAML)
  bool infinity = false;    ///< "inf" and ".inf" read as +infinity (scenario files)
  bool pi = false;          ///< angles such as "pi", "-pi/2", "2*pi/3", "0.5*pi" (DH tables)
};

/// What scan_number made of a text.
enum class NumberScan { kOk, kNotANumber, kOutOfRange };

/// The whole text as a double, nan and inf included as from_chars reads them; the building block
/// of parse_number, for readers that tell "not a number" from "out of range" (the CSV reader).
[[nodiscard]] NumberScan scan_number(std::string_view text, double& value) noexcept;

/// The common case, a finite number without a leading '+', in one from_chars call; the CSV
/// reader's fast path (inline: it runs for every cell of a replayed log).
[[nodiscard]] inline bool parse_plain_number(std::string_view text, double& value) noexcept {
  if (text.empty() || text.front() == '+') return false;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && ptr == text.data() + text.size() && std::isfinite(value);
}

/// The whole text as one finite number (or what `rules` add), or nothing.
[[nodiscard]] std::optional<double> parse_number(std::string_view text, NumberRules rules = {});

/// Appends format_number(value) to `out` without a temporary string.
void append_number(std::string& out, double value);

/// The shortest text that reads back to the same double (std::to_chars): "0.1", "-2.5e-07",
/// "inf", "nan". What the CSV, URDF, metrics and scenario writers write.
[[nodiscard]] std::string format_number(double value);

}  // namespace extwrench
