#pragma once
// Test support: the message of the exception a call must throw.
#include <string>

#include <gtest/gtest.h>

namespace radiant::testing {

// Runs `f`, expecting an exception of type E, and returns its what(); a failure if none is thrown.
template <class E, class F>
std::string thrownMessage(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception";
  return {};
}

}  // namespace radiant::testing
