#include "extwrench/io/text_quoting.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>

namespace extwrench {

std::string double_quoted(std::string_view text) {
  std::string out = "\"";
  out.reserve(text.size() + 2);
  for (const char ch : text) {
    switch (ch) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      default: {
        const auto byte = static_cast<unsigned char>(ch);
        if (byte < 0x20 || byte == 0x7F) {
          char escape[7];
          std::snprintf(escape, sizeof escape, "\\u%04X", byte);
          out += escape;
        } else {
          out += ch;
        }
      }
    }
  }
  return out + '"';
}

std::string yaml_scalar(std::string_view text) {
  // YAML 1.1 words a reader may take for null or a boolean (yaml-cpp reads several of them so).
  static constexpr std::array<std::string_view, 11> kWords = {
      "null", "true", "false", "yes", "no", "on", "off", "y", "n", "~", "none"};
  const auto safe = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.' || c == '/' ||
           c == '-' || c == '+';
  };
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  const bool plain = !text.empty() && text.front() != '-' && text.front() != '+' &&
                     std::all_of(text.begin(), text.end(), safe) &&
                     std::find(kWords.begin(), kWords.end(), lower) == kWords.end();
  return plain ? std::string(text) : double_quoted(text);
}

}  // namespace extwrench
