// Helpers shared by the unit tests.
#pragma once

#include <string>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::testing_util {

// The message of the InputError (or GeometryError) thrown by `f`, or
// "(no error)" if it throws none, so that a missing error shows in the failure.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace crowdrecon::testing_util
