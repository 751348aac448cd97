#include "dyad/mcap/status.hpp"

namespace dyad::mcap {

Status::Status(Code code, std::string_view context, std::string_view detail) : code_(code) {
  message_.reserve(context.size() + detail.size() + 2);
  message_.append(context);
  if (!context.empty() && !detail.empty()) message_.append(": ");
  message_.append(detail);
}

std::string Status::ToString() const {
  const char* prefix = "OK";
  switch (code_) {
    case Code::kOk: return prefix;
    case Code::kInvalidArgument: prefix = "Invalid argument: "; break;
    case Code::kFailedPrecondition: prefix = "Failed precondition: "; break;
    case Code::kIOError: prefix = "IO error: "; break;
    case Code::kDataLoss: prefix = "Data loss: "; break;
  }
  return prefix + message_;
}

}  // namespace dyad::mcap
