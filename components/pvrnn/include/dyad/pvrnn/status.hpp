// dyad/pvrnn/status.hpp: the result type of every fallible call in the PV-RNN library.
//
// Contract
// - `Status` is cheap on success (no allocation) and carries a code plus a message on failure.
//   Messages start with the subject (usually the file name) followed by what is wrong, e.g.
//   "model.dpvrnn: truncated: 812 bytes, header needs at least 4096".
// - `StatusOr<T>` holds either a value or a non-OK status; `value()` on an error aborts (a broken
//   caller assumption), so check `ok()` first.
// - The library never throws across its public API for bad input or I/O; it returns these.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

namespace dyad::pvrnn {

class Status {
 public:
  enum class Code { kOk = 0, kInvalidArgument, kNotFound, kIoError, kCorrupted, kUnsupported };

  Status() = default;  // OK
  static Status Ok() { return Status(); }
  static Status InvalidArgument(std::string msg) { return Status(Code::kInvalidArgument, std::move(msg)); }
  static Status NotFound(std::string msg) { return Status(Code::kNotFound, std::move(msg)); }
  static Status IoError(std::string msg) { return Status(Code::kIoError, std::move(msg)); }
  static Status Corrupted(std::string msg) { return Status(Code::kCorrupted, std::move(msg)); }
  static Status Unsupported(std::string msg) { return Status(Code::kUnsupported, std::move(msg)); }

  bool ok() const { return code_ == Code::kOk; }
  Code code() const { return code_; }
  const std::string& message() const { return message_; }
  std::string ToString() const { return ok() ? std::string("OK") : message_; }

 private:
  Status(Code code, std::string msg) : code_(code), message_(std::move(msg)) {}
  Code code_ = Code::kOk;
  std::string message_;
};

template <typename T>
class StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  StatusOr(Status status) : status_(std::move(status)) {  // NOLINT: implicit by design
    if (status_.ok()) Die("StatusOr constructed from an OK status without a value");
  }

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  const T& value() const& { Check(); return *value_; }
  T& value() & { Check(); return *value_; }
  T&& value() && { Check(); return std::move(*value_); }
  const T* operator->() const { Check(); return &*value_; }
  T* operator->() { Check(); return &*value_; }

 private:
  void Check() const { if (!value_) Die(("StatusOr::value() on error: " + status_.message()).c_str()); }
  [[noreturn]] static void Die(const char* what) { std::fprintf(stderr, "%s\n", what); std::abort(); }
  Status status_;
  std::optional<T> value_;
};

}  // namespace dyad::pvrnn
