// Progress of the programs' long loops (simulating a scenario, replaying a log) on stderr: on a
// terminal one line rewritten in place; elsewhere (a CI log, a file, a pipe) a whole line every
// kLineInterval, so that a long job shows it is alive without flooding the log. With a known
// total, the percentage and the estimated time left are appended.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>

namespace extwrench::detail {

class ProgressLine {
 public:
  static constexpr std::chrono::seconds kLineInterval{10};

  /// Looks at the clock every `every` counts (a power of two: the test is one mask per call) and
  /// rewrites the terminal line at most once per `interval`. total > 0: the count's end.
  ProgressLine(bool on, long every, std::chrono::milliseconds interval, long total = 0)
      : on_(on),
        terminal_(::isatty(STDERR_FILENO) != 0),
        mask_(every - 1),
        interval_(terminal_ ? interval : std::chrono::milliseconds(kLineInterval)),
        total_(total),
        start_(std::chrono::steady_clock::now()),
        last_(terminal_ ? std::chrono::steady_clock::time_point{} : start_) {}
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// When due at `count`: TEXT from the printf format, then "  42 %, ETA 1 min 3 s" with a total;
  /// on a terminal "\r  TEXT   " (the trailing blanks erase a longer previous line), else a line.
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
    if (total_ > 0) text += share(count, now);
    if (terminal_) {
      std::fprintf(stderr, "\r  %s   ", text.c_str());
    } else {
      std::fprintf(stderr, "extwrench: progress: %s\n", text.c_str());
    }
    std::fflush(stderr);
    shown_ = true;
  }

  /// Clears the terminal line, if one was shown.
  void done() const {
    if (shown_ && terminal_) std::fprintf(stderr, "\r%*s\r", 60, "");
  }

 private:
  // "  42 %, ETA 1 min 3 s": the rate so far continued to the total.
  std::string share(long count, std::chrono::steady_clock::time_point now) const {
    const double fraction = std::clamp(static_cast<double>(count) / total_, 0.0, 1.0);
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    char buf[64];
    if (fraction > 0.0) {
      const long left = std::lround(elapsed * (1.0 - fraction) / fraction);
      std::snprintf(buf, sizeof buf, "  %3.0f %%, ETA %ld min %ld s", 100.0 * fraction, left / 60,
                    left % 60);
    } else {
      std::snprintf(buf, sizeof buf, "  %3.0f %%", 100.0 * fraction);
    }
    return buf;
  }

  bool on_;
  bool terminal_;
  long mask_;
  std::chrono::milliseconds interval_;
  long total_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_;
  bool shown_ = false;
};

}  // namespace extwrench::detail
