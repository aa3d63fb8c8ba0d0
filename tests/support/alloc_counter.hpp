// Counts heap allocations made by the whole process (malloc & co. and every global operator new
// are interposed), to prove that real-time functions allocate nothing. Not only Eigen's flag:
// std::vector or a stray std::string in the hot path are caught too, and so are allocations
// inside KDL, Eigen or the standard library. One counter for the tests and the benchmarks
// (which compile this file in and report it per call as the counter "allocs").
#pragma once

#include <cstddef>

namespace extwrench::test {

/// False in sanitizer builds, whose runtimes own malloc: the allocation tests skip there.
bool allocation_counting_available();

/// Allocations made by the whole process since it started.
[[nodiscard]] std::size_t allocation_count() noexcept;

/// Counts allocations between construction and count().
class AllocationCounter {
 public:
  AllocationCounter();
  [[nodiscard]] std::size_t count() const;

 private:
  std::size_t start_;
};

}  // namespace extwrench::test
