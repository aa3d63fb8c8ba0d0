#pragma once
// What kind of build the tests run in: time and memory bounds hold for the optimised build only
// (AddressSanitizer's shadow memory and quarantine, and -O1, measure the sanitizer instead).

namespace extwrench::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif

}  // namespace extwrench::test
