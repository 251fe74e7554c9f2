#include "core/kind.h"

#include <string>

#include "core/error.h"

namespace ibrdf {

void UnhandledKind(const char* enum_name, int value) {
  throw InternalError(std::string("unhandled ") + enum_name + " value " + std::to_string(value));
}

}  // namespace ibrdf
