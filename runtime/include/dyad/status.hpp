// dyad/status.hpp — the result of an operation that can fail on bad input or a broken
// environment. The one result type of every dyad library (runtime, PV-RNN, MCAP, CLI).
//
// Status is cheap on success (no allocation) and on failure carries a code and a message that
// already names its context, file first ("graph.yaml:12:5: components.mixer.params.gain = -1:
// must be >= 0"; "run.mcap: chunk at offset 4096: CRC mismatch"). Nothing in dyad throws across a
// library's public API or the plugin boundary: calls return Status or StatusOr<T>.
//
//   dyad::Status s = component.Configure(ctx);
//   if (!s.ok()) std::cerr << s.ToString() << "\n";
//
// StatusOr<T> holds either a T or a non-OK Status; value() on an error aborts with the message
// (a broken caller assumption), so check ok() first. Header-only: libraries without DDS use it.
//
// Both are [[nodiscard]]: an error dropped by accident is a warning (an error in CI). A caller
// that means to drop one says so with IgnoreError(), the reason in a comment beside it.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace dyad {

class [[nodiscard]] Status {
 public:
  enum class Code {
    kOk,
    kInvalidArgument,     // the caller or the user passed something unusable
    kNotFound,            // a file, type or name that does not exist
    kFailedPrecondition,  // not allowed in the current state (Write after Close, ABI mismatch)
    kIOError,             // the operating system refused (open, read, write)
    kDataLoss,            // a file or payload is damaged (bad CRC, truncated, not our format)
    kUnimplemented,       // a valid request this version does not support (file version, IDL construct)
    kInternal,            // a dependency failed in a way the caller cannot fix (DDS entity creation)
  };

  Status() = default;  // OK
  static Status OK() { return Status(); }
  static Status InvalidArgument(std::string msg) { return Status(Code::kInvalidArgument, std::move(msg)); }
  static Status NotFound(std::string msg) { return Status(Code::kNotFound, std::move(msg)); }
  static Status FailedPrecondition(std::string msg) { return Status(Code::kFailedPrecondition, std::move(msg)); }
  static Status IOError(std::string msg) { return Status(Code::kIOError, std::move(msg)); }
  static Status DataLoss(std::string msg) { return Status(Code::kDataLoss, std::move(msg)); }
  static Status Unimplemented(std::string msg) { return Status(Code::kUnimplemented, std::move(msg)); }
  static Status Internal(std::string msg) { return Status(Code::kInternal, std::move(msg)); }
  // Two-part forms: "context: detail" (context is usually the file).
  static Status InvalidArgument(std::string_view context, std::string_view detail) { return Join(Code::kInvalidArgument, context, detail); }
  static Status FailedPrecondition(std::string_view context, std::string_view detail) { return Join(Code::kFailedPrecondition, context, detail); }
  static Status IOError(std::string_view context, std::string_view detail) { return Join(Code::kIOError, context, detail); }
  static Status DataLoss(std::string_view context, std::string_view detail) { return Join(Code::kDataLoss, context, detail); }

  // The same code, with "context: " before the message: layers add where, never change what.
  Status WithContext(std::string_view context) const {
    if (ok()) return *this;
    return Join(code_, context, message_);
  }

  bool ok() const { return code_ == Code::kOk; }
  Code code() const { return code_; }
  // Drops this result on purpose (a best-effort write the next one repeats; cleanup after the
  // first error, which is the one reported). Say why beside the call.
  void IgnoreError() const {}
  // Empty when ok().
  const std::string& message() const { return message_; }
  // "OK" or "<code name>: <message>", e.g. "I/O error: run.mcap: open: Permission denied".
  std::string ToString() const { return ok() ? std::string("OK") : std::string(CodeName(code_)) + ": " + message_; }
  static const char* CodeName(Code code) {
    switch (code) {
      case Code::kOk: return "OK";
      case Code::kInvalidArgument: return "invalid argument";
      case Code::kNotFound: return "not found";
      case Code::kFailedPrecondition: return "failed precondition";
      case Code::kIOError: return "I/O error";
      case Code::kDataLoss: return "data loss";
      case Code::kUnimplemented: return "unimplemented";
      case Code::kInternal: return "internal error";
    }
    return "error";
  }

 private:
  Status(Code code, std::string msg) : code_(code), message_(std::move(msg)) {}
  static Status Join(Code code, std::string_view context, std::string_view detail) {
    std::string m;
    m.reserve(context.size() + detail.size() + 2);
    m.append(context);
    if (!context.empty() && !detail.empty()) m.append(": ");
    m.append(detail);
    return Status(code, std::move(m));
  }
  Code code_ = Code::kOk;
  std::string message_;
};

// Either a value or the Status saying why there is none.
// REQUIRES: the Status given to the constructor is not OK.
template <class T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  StatusOr(Status status) : status_(std::move(status)) {  // NOLINT: implicit by design
    if (status_.ok()) Die("StatusOr constructed from an OK status without a value");
  }
  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }
  // REQUIRES: ok(); aborts with the error otherwise.
  T& value() & { Check(); return *value_; }
  const T& value() const& { Check(); return *value_; }
  T&& value() && { Check(); return std::move(*value_); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  void Check() const {
    if (!value_) Die(("StatusOr::value() on an error: " + status_.ToString()).c_str());
  }
  [[noreturn]] static void Die(const char* what) {
    std::fprintf(stderr, "dyad: %s\n", what);
    std::abort();
  }
  Status status_;
  std::optional<T> value_;
};

}  // namespace dyad
