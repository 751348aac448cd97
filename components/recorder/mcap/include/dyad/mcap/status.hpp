// Status and StatusOr<T>: how every public call of dyad_mcap reports failure.
//
// Contract:
//   - No exception escapes the public API of dyad_mcap; failures come back as a Status.
//   - A Status is cheap when ok (no allocation). A failed Status carries a code and a message whose
//     first part is the file it concerns, e.g.
//       "/tmp/run.mcap: chunk at offset 4096: CRC mismatch (stored 0x1234abcd, computed 0x0badf00d)".
//   - StatusOr<T> holds either a value or a failed Status; value() REQUIRES ok().
//
// Usage:
//   dyad::mcap::StatusOr<dyad::mcap::Reader> reader = dyad::mcap::Reader::Open(path);
//   if (!reader.ok()) { std::cerr << reader.status().ToString() << "\n"; return 1; }
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace dyad::mcap {

class Status {
 public:
  enum class Code {
    kOk,
    kInvalidArgument,     // the caller passed something unusable (bad option, unknown channel id)
    kFailedPrecondition,  // the call is not allowed in the object's state (e.g. Write after Close)
    kIOError,             // the operating system refused (open, write, read)
    kDataLoss,            // the file is damaged (bad CRC, undecodable chunk, not MCAP)
  };

  // An ok status.
  Status() = default;

  static Status Ok() { return Status(); }
  static Status InvalidArgument(std::string_view context, std::string_view detail) {
    return Status(Code::kInvalidArgument, context, detail);
  }
  static Status FailedPrecondition(std::string_view context, std::string_view detail) {
    return Status(Code::kFailedPrecondition, context, detail);
  }
  static Status IOError(std::string_view context, std::string_view detail) {
    return Status(Code::kIOError, context, detail);
  }
  static Status DataLoss(std::string_view context, std::string_view detail) {
    return Status(Code::kDataLoss, context, detail);
  }

  bool ok() const { return code_ == Code::kOk; }
  Code code() const { return code_; }
  // "context: detail"; empty when ok.
  const std::string& message() const { return message_; }
  // "OK" or e.g. "IO error: /tmp/x.mcap: open: Permission denied".
  std::string ToString() const;

 private:
  Status(Code code, std::string_view context, std::string_view detail);

  Code code_ = Code::kOk;
  std::string message_;
};

// A value or the Status explaining why there is none.
template <typename T>
class StatusOr {
 public:
  // REQUIRES: !status.ok() (an ok StatusOr must carry a value).
  StatusOr(Status status) : status_(std::move(status)) { assert(!status_.ok()); }  // NOLINT
  StatusOr(T value) : value_(std::move(value)) {}                                   // NOLINT

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }

  // REQUIRES: ok().
  T& value() & { assert(ok()); return *value_; }
  const T& value() const& { assert(ok()); return *value_; }
  T&& value() && { assert(ok()); return std::move(*value_); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  Status status_;
  std::optional<T> value_;
};

}  // namespace dyad::mcap
