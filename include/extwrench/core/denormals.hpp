// Flush-to-zero for a real-time thread (docs/estimator.md#hard-real-time). A subnormal operand or
// result (|x| < 2.2e-308) takes a slow path in the FPU: the estimator's update with subnormal
// joint velocities takes about 25 % longer, with velocities of 1e-300 (whose products underflow)
// about 30 % (BENCHMARKS.md). Real measurements are never that small, but a signal decaying
// toward zero with nothing driving it (a simulation at exact rest) crosses the range after
// ~7 s at K = 100 s⁻¹. The thread's floating-point mode belongs to the caller, so this is a scoped
// guard for the loop rather than a hidden switch inside update().
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#define EXTWRENCH_HAS_FLUSH_DENORMALS 1
#else
#define EXTWRENCH_HAS_FLUSH_DENORMALS 0
#endif

namespace extwrench {

/// While alive, the calling thread treats subnormal operands as zero (DAZ) and flushes subnormal
/// results to zero (FTZ); the destructor restores the thread's previous mode. On x86-64 (SSE's
/// MXCSR, which double arithmetic uses there); elsewhere it changes nothing and supported() is
/// false. Results differ from IEEE arithmetic only where a subnormal occurs. noexcept.
class ScopedFlushDenormals {
 public:
  ScopedFlushDenormals() noexcept {
#if EXTWRENCH_HAS_FLUSH_DENORMALS
    saved_ = _mm_getcsr();
    _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero);
#endif
  }
  ~ScopedFlushDenormals() {
#if EXTWRENCH_HAS_FLUSH_DENORMALS
    _mm_setcsr(saved_);
#endif
  }
  ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
  ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;

  /// Whether this platform's guard does anything.
  [[nodiscard]] static constexpr bool supported() noexcept {
    return EXTWRENCH_HAS_FLUSH_DENORMALS != 0;
  }

 private:
#if EXTWRENCH_HAS_FLUSH_DENORMALS
  static constexpr unsigned kFlushToZero = 0x8000u;       // MXCSR.FTZ
  static constexpr unsigned kDenormalsAreZero = 0x0040u;  // MXCSR.DAZ
  unsigned saved_ = 0;
#endif
};

}  // namespace extwrench
