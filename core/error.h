// Errors and internal checks shared by every stage.
//
// Bad user input (a corrupt file, an unknown key, a missing photo) is an ibrdf::Error whose message
// names the file, the field or line, and what was expected. It is caught once, in apps/main.cc, which
// prints it and exits non-zero. Broken internal invariants are IBRDF_CHECK failures: they stay on in
// release builds and throw InternalError, which main reports as a bug.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace ibrdf {

// Bad input from the user: the message already names the file and the field.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A broken internal invariant: a bug in ibrdf, never the user's fault.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// Throws Error("<where>: <what>"). `where` is a file, optionally with a field path or line.
[[noreturn]] void ThrowError(const std::string& where, const std::string& what);

namespace internal {
[[noreturn]] void CheckFailed(const char* file, int line, const char* condition, const std::string& message);
}  // namespace internal

}  // namespace ibrdf

// Internal invariant, on in every build type. Usage: IBRDF_CHECK(n > 0) << "n=" << n;
#define IBRDF_CHECK(condition) \
  if (condition) {             \
  } else                       \
    ::ibrdf::internal::CheckMessage(__FILE__, __LINE__, #condition).stream()

namespace ibrdf::internal {
// Collects the streamed message and throws InternalError when destroyed.
class CheckMessage {
 public:
  CheckMessage(const char* file, int line, const char* condition) : file_(file), line_(line), condition_(condition) {}
  [[noreturn]] ~CheckMessage() noexcept(false) { CheckFailed(file_, line_, condition_, stream_.str()); }
  std::ostringstream& stream() { return stream_; }

 private:
  const char* file_;
  int line_;
  const char* condition_;
  std::ostringstream stream_;
};
}  // namespace ibrdf::internal

// Option checks for `bool XOptions::Check(std::string* why) const` (in the spirit of COLMAP's
// CHECK_OPTION_*): on failure `*why` names the constraint and the value, e.g.
// "max_theta_i_deg <= 90 failed: max_theta_i_deg = 95", and Check returns false.
//   IBRDF_CHECK_OPTION(!name.empty());
//   IBRDF_CHECK_OPTION_GT(pixel_stride, 0);
//   IBRDF_CHECK_OPTION_LE(max_theta_i_deg, 90.0);
#define IBRDF_CHECK_OPTION(condition)                      \
  do {                                                     \
    if (!(condition)) {                                    \
      if (why) *why = std::string(#condition) + " failed"; \
      return false;                                        \
    }                                                      \
  } while (0)

#define IBRDF_CHECK_OPTION_OP(value, op, bound)                                                \
  do {                                                                                         \
    if (!((value)op(bound))) {                                                                 \
      if (why) {                                                                               \
        std::ostringstream ibrdf_option_message;                                               \
        ibrdf_option_message << #value " " #op " " #bound " failed: " #value " = " << (value); \
        *why = ibrdf_option_message.str();                                                     \
      }                                                                                        \
      return false;                                                                            \
    }                                                                                          \
  } while (0)

#define IBRDF_CHECK_OPTION_GT(value, bound) IBRDF_CHECK_OPTION_OP(value, >, bound)
#define IBRDF_CHECK_OPTION_GE(value, bound) IBRDF_CHECK_OPTION_OP(value, >=, bound)
#define IBRDF_CHECK_OPTION_LT(value, bound) IBRDF_CHECK_OPTION_OP(value, <, bound)
#define IBRDF_CHECK_OPTION_LE(value, bound) IBRDF_CHECK_OPTION_OP(value, <=, bound)
#define IBRDF_CHECK_OPTION_EQ(value, bound) IBRDF_CHECK_OPTION_OP(value, ==, bound)
// value in [low, high]; NaN fails.
#define IBRDF_CHECK_OPTION_RANGE(value, low, high) \
  do {                                             \
    IBRDF_CHECK_OPTION_GE(value, low);             \
    IBRDF_CHECK_OPTION_LE(value, high);            \
  } while (0)
