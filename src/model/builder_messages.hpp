// What ModelBuilder's build and lock_joint share: the axis threshold and how their messages
// print numbers and name the source. Internal to src/model.
#pragma once

#include <cstdio>
#include <string>

namespace extwrench::model_detail {

/// |axis| below this is a zero axis.
inline constexpr double kMinAxisNorm = 1e-12;

/// A number in a message: 9 significant digits, as the text files the models come from.
inline std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

/// "SOURCE: " (the file, or what built the element), or nothing for an unnamed source.
inline std::string prefix(const std::string& source) {
  return source.empty() ? std::string() : source + ": ";
}

}  // namespace extwrench::model_detail
