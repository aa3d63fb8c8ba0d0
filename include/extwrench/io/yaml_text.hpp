// Text written into the YAML files the tools write (CALIB.yaml, a scheme's config.yaml): one
// quoting rule, so that any string (a path with ": " or "#", a log name with control bytes)
// reads back as itself.
#pragma once

#include <string>
#include <string_view>

namespace extwrench {

/// `text` as a YAML double-quoted scalar that reads back byte for byte: '"' and '\' escaped,
/// control characters (and DEL) as YAML escapes (\0, \t, \n, \r, \xHH); other bytes as they are
/// (UTF-8 passes through).
[[nodiscard]] std::string yaml_quoted(std::string_view text);

/// `text` as it is when YAML reads it back as that very string as a plain scalar (letters,
/// digits and _ . / + -, not starting with - or +, not a word such as null, true or no), else
/// yaml_quoted: paths and names stay readable, and any other reads back too.
[[nodiscard]] std::string yaml_scalar(std::string_view text);

}  // namespace extwrench
