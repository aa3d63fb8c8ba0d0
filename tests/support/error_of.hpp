// The message of an expected extwrench::Error, for tests that check what a user is told.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "extwrench/core/error.hpp"

namespace extwrench::test {

/// The message of the extwrench::Error that `f` throws; "" and a test failure if it throws none.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an extwrench::Error";
  return "";
}

}  // namespace extwrench::test
