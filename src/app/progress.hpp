// One progress line on stderr, rewritten in place, for the programs' long loops (simulating a
// scenario, replaying a log). The callers turn it on when stderr is a terminal.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <string>

namespace extwrench::detail {

class ProgressLine {
 public:
  /// Looks at the clock every `every` counts (a power of two: the test is one mask per call) and
  /// rewrites the line at most once per `interval`.
  ProgressLine(bool on, long every, std::chrono::milliseconds interval)
      : on_(on), mask_(every - 1), interval_(interval) {}
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// When due at `count`: "\r  TEXT   " with TEXT from the printf format (the trailing blanks
  /// erase the end of a longer previous line).
  [[gnu::format(printf, 3, 4)]] void update(long count, const char* format, ...) {
    if (!on_ || (count & mask_) != 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < interval_) return;
    last_ = now;
    va_list args;
    va_start(args, format);
    va_list again;
    va_copy(again, args);
    const int size = std::vsnprintf(nullptr, 0, format, args);
    std::string text(static_cast<std::size_t>(std::max(size, 0)), '\0');
    if (size > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
    va_end(again);
    va_end(args);
    std::fprintf(stderr, "\r  %s   ", text.c_str());
    std::fflush(stderr);
    shown_ = true;
  }

  /// Clears the line, if one was shown.
  void done() const {
    if (shown_) std::fprintf(stderr, "\r%*s\r", 60, "");
  }

 private:
  bool on_;
  long mask_;
  std::chrono::milliseconds interval_;
  std::chrono::steady_clock::time_point last_{};
  bool shown_ = false;
};

}  // namespace extwrench::detail
