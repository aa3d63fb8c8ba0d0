// Counts heap allocations made by the whole process (global operator new and malloc), to prove
// that real-time functions allocate nothing. Not only Eigen's flag: std::vector or a stray
// std::string in the hot path are caught too.
#pragma once

#include <cstddef>

namespace extwrench::test {

/// False in sanitizer builds, whose runtimes own malloc: the allocation tests skip there.
bool allocation_counting_available();

/// Counts allocations between construction and count().
class AllocationCounter {
 public:
  AllocationCounter();
  [[nodiscard]] std::size_t count() const;

 private:
  std::size_t start_;
};

}  // namespace extwrench::test
