#include "core/error.h"

#include <fmt/format.h>

namespace arcwheel {

int ExitStatus(ErrorCode code) noexcept {
  switch (code) {
    case ErrorCode::kInvalidOption:
      return 2;
    case ErrorCode::kBadInput:
      return 3;
    case ErrorCode::kIo:
      return 4;
    case ErrorCode::kFitFailed:
      return 5;
    case ErrorCode::kInterrupted:
      return 130;
    case ErrorCode::kInternal:
      return 70;
  }
  return 70;
}

std::string_view ErrorCodeName(ErrorCode code) noexcept {
  switch (code) {
    case ErrorCode::kInvalidOption:
      return "invalid option";
    case ErrorCode::kBadInput:
      return "bad input";
    case ErrorCode::kIo:
      return "I/O error";
    case ErrorCode::kFitFailed:
      return "fit failed";
    case ErrorCode::kInterrupted:
      return "interrupted";
    case ErrorCode::kInternal:
      return "internal error";
  }
  return "internal error";
}

std::string JoinProblems(const std::vector<std::string>& problems) {
  return fmt::format("{}", fmt::join(problems, "; "));
}

void ThrowIfProblems(ErrorCode code, std::string_view stage, const std::vector<std::string>& problems) {
  if (!problems.empty()) throw Error(code, stage, JoinProblems(problems));
}

}  // namespace arcwheel
