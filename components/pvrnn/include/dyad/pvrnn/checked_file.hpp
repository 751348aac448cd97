// dyad/pvrnn/checked_file.hpp: the container of dyad's binary files (PV-RNN models `.dpvrnn`,
// observers `.dobs`): one self-describing, versioned, checksummed file written atomically.
//
// Layout (integers and doubles little-endian):
//   8 bytes magic | u32 version | u32 flags (0) | u64 J | J bytes JSON header | payload | u32 CRC-32
// The CRC (zlib) covers every byte before it. Each format names its magic, version and what the
// file is called in messages ("dyad PV-RNN model file"), and decides what the JSON and payload hold.
//
//   std::string bytes = BeginCheckedFile(kMagic, 1, header.dump());
//   AppendDouble(bytes, x); ...
//   Status s = FinishCheckedFile(bytes, path);            // path.tmp, then rename
//
//   StatusOr<std::string> bytes = ReadWholeFile(path, "observer file");
//   StatusOr<CheckedFileView> v = OpenCheckedFile(*bytes, path, kMagic, 1, "dyad observer file");
//   if (v->crc_ok) ... json::parse(v->json) ... ReadDouble(*bytes, v->payload_at + 8 * i)
//
// Errors start with the path: NotFound (cannot open), InvalidArgument (a folder), IOError (read or
// write failed), DataLoss (bad magic; shorter than the fixed header; header longer than the file),
// Unimplemented (another format version). A checksum mismatch is not an error of OpenCheckedFile:
// formats report it themselves (the model file tells a truncated from a corrupted one).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "dyad/status.hpp"

namespace dyad::pvrnn {

// Magic, version, flags and the JSON header; append the payload, then FinishCheckedFile.
std::string BeginCheckedFile(const char (&magic)[8], uint32_t version, std::string_view json);
// Appends the CRC and writes `bytes` to `path` through `path.tmp` and a rename, so a crash never
// leaves a half file under `path`.
Status FinishCheckedFile(std::string& bytes, const std::string& path);

void AppendDouble(std::string& bytes, double value);
// REQUIRES at + 8 <= bytes.size().
double ReadDouble(const std::string& bytes, size_t at);

// The whole file. `what` names it in the folder error ("model file": "P: is a folder, not a model file").
StatusOr<std::string> ReadWholeFile(const std::string& path, const std::string& what);

struct CheckedFileView {
  std::string_view json;     // the JSON header
  size_t payload_at = 0;     // offset of the payload
  size_t payload_bytes = 0;  // its length (up to the CRC)
  bool crc_ok = false;
};
// Checks magic, size, version and the header length of `bytes` (read from `path`). `kind` names
// the format in the bad-magic error ("not a <kind> (bad magic)").
StatusOr<CheckedFileView> OpenCheckedFile(const std::string& bytes, const std::string& path, const char (&magic)[8],
                                          uint32_t version, const std::string& kind);

}  // namespace dyad::pvrnn
