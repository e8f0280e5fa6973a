#pragma once
// ARCWHEEL_CHECK(cond) << "context";  throws Error{kInternal} when cond is false.
// For invariants of our own code only; bad input is reported with Error{kBadInput}.

#include <sstream>
#include <string>

#include "core/error.h"

namespace arcwheel::internal {

class CheckFailure {
 public:
  CheckFailure(const char* condition, const char* file, int line) {
    stream_ << file << ":" << line << ": check failed: " << condition << " ";
  }
  CheckFailure(const CheckFailure&) = delete;
  CheckFailure& operator=(const CheckFailure&) = delete;
  // Throwing from a destructor is deliberate: the temporary dies at the end of the statement.
  ~CheckFailure() noexcept(false) { throw Error(ErrorCode::kInternal, "arcwheel", stream_.str()); }
  template <typename T>
  CheckFailure& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  std::ostringstream stream_;
};

}  // namespace arcwheel::internal

#define ARCWHEEL_CHECK(condition) \
  if (condition) {                \
  } else                          \
    ::arcwheel::internal::CheckFailure(#condition, __FILE__, __LINE__)
