#include "extwrench/io/number_text.hpp"

#include <array>
#include <limits>
#include <numbers>

namespace extwrench {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::optional<double> finite(std::string_view s) {
  double v = 0.0;
  if (scan_number(s, v) != NumberScan::kOk || !std::isfinite(v)) return std::nullopt;
  return v;
}

// "[sign][factor*]pi[/divisor]": factor and divisor unsigned finite numbers, divisor != 0.
std::optional<double> pi_expression(std::string_view s) {
  double sign = 1.0;
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
    sign = s.front() == '-' ? -1.0 : 1.0;
    s.remove_prefix(1);
  }
  const auto pos = s.find("pi");
  if (pos == std::string_view::npos) return std::nullopt;
  const auto is_sign = [](char c) { return c == '-' || c == '+'; };
  double v = std::numbers::pi;
  const std::string_view before = s.substr(0, pos);
  const std::string_view after = s.substr(pos + 2);
  if (!before.empty()) {
    if (before.back() != '*' || is_sign(before.front())) return std::nullopt;
    const auto f = finite(before.substr(0, before.size() - 1));
    if (!f) return std::nullopt;
    v *= *f;
  }
  if (!after.empty()) {
    if (after.front() != '/' || after.size() < 2 || is_sign(after[1])) return std::nullopt;
    const auto f = finite(after.substr(1));
    if (!f || *f == 0.0) return std::nullopt;
    v /= *f;
  }
  return sign * v;
}

}  // namespace

NumberScan scan_number(std::string_view text, double& value) noexcept {
  if (text.empty()) return NumberScan::kNotANumber;
  const char* p = text.data();
  const char* const end = text.data() + text.size();
  if (*p == '+') {  // from_chars rejects a leading '+'
    ++p;
    if (p != end && (*p == '+' || *p == '-')) return NumberScan::kNotANumber;
  }
  const auto [ptr, ec] = std::from_chars(p, end, value);
  if (ec == std::errc::result_out_of_range) return NumberScan::kOutOfRange;
  if (ec != std::errc() || ptr != end) return NumberScan::kNotANumber;
  return NumberScan::kOk;
}

std::optional<double> parse_number(std::string_view text, NumberRules rules) {
  const std::string_view s = rules.trim_space ? trim(text) : text;
  if (const auto v = finite(s)) return v;
  if (rules.infinity && (s == "inf" || s == ".inf")) return std::numeric_limits<double>::infinity();
  if (rules.pi) return pi_expression(s);
  return std::nullopt;
}

void append_number(std::string& out, double value) {
  std::array<char, 32> text{};  // the shortest form of a double has at most 24 characters
  const auto [ptr, ec] = std::to_chars(text.data(), text.data() + text.size(), value);
  (void)ec;  // cannot fail with 32 characters
  out.append(text.data(), ptr);
}

std::string format_number(double value) {
  std::string s;
  append_number(s, value);
  return s;
}

}  // namespace extwrench
