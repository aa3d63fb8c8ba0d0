// Strings written into the YAML and JSON files the tools write (CALIB.yaml, a scheme's
// config.yaml, metrics.json): one quoting rule, so that any string (a path with ": " or "#", a
// log name with control bytes) reads back as itself.
#pragma once

#include <string>
#include <string_view>

namespace extwrench {

/// `text` as a double-quoted string that YAML and JSON both read back byte for byte: the escapes
/// the two share (\" \\ \n \r \t, and \u00XX for the other control characters and DEL); other
/// bytes as they are (UTF-8 passes through).
[[nodiscard]] std::string double_quoted(std::string_view text);

/// `text` as it is when YAML reads it back as that very string as a plain scalar (letters,
/// digits and _ . / + -, not starting with - or +, not a word such as null, true or no), else
/// double_quoted: paths and names stay readable, and any other reads back too.
[[nodiscard]] std::string yaml_scalar(std::string_view text);

}  // namespace extwrench
