#include "core/error.h"

namespace ibrdf {

void ThrowError(const std::string& where, const std::string& what) {
  throw Error(where.empty() ? what : where + ": " + what);
}

namespace internal {
void CheckFailed(const char* file, int line, const char* condition, const std::string& message) {
  std::ostringstream out;
  out << "internal check failed at " << file << ":" << line << ": " << condition;
  if (!message.empty()) out << " (" << message << ")";
  throw InternalError(out.str());
}
}  // namespace internal

}  // namespace ibrdf
