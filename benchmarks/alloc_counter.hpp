// Process-wide heap allocation counter of the benchmark binary: malloc & co. and every global
// operator new are interposed (alloc_counter.cpp), so allocations inside KDL, Eigen or the
// standard library are counted too. Reported per call as the benchmark counter "allocs".
#pragma once

#include <cstddef>

namespace extwrench::bench {

/// Allocations made by the whole process since it started.
std::size_t allocation_count() noexcept;

}  // namespace extwrench::bench
