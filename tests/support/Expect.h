#pragma once
// Test support: the exception a call must throw.
#include <string>

#include <gtest/gtest.h>

#include "api/Types.h"

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

// Runs `f`, expecting an api::ApiError (a request refused with a status and a pointer), and returns
// it; a failure, and status 0, if none is thrown.
template <class F>
api::ApiError thrownApiError(F&& f) {
  try {
    f();
  } catch (const api::ApiError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an api::ApiError";
  return api::ApiError(0, "", "", "", "");
}

}  // namespace radiant::testing
