// The message of the ibrdf::Error a call throws ("" when it throws none), for tests of error texts.
#pragma once

#include <functional>
#include <string>

#include "core/error.h"

namespace ibrdf::testing {

inline std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace ibrdf::testing
