// Helpers shared by the libFuzzer harnesses of tests/fuzz (one target per file, each thin: it
// hands the bytes to one reader and checks the error contract).
//
// The contract every harness checks, beyond what the sanitizers and libFuzzer catch (crash,
// abort, uncaught exception, std::terminate, out-of-bounds, leak, over-allocation with
// -malloc_limit_mb): a rejected input gives a non-OK Status with a message that names the input
// (the file path, or the graph file). Require() aborts with the message otherwise, so libFuzzer
// records the input as a crash.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace dyad::fuzz {

inline void Require(bool ok, std::string_view what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz contract violated: %.*s\n", static_cast<int>(what.size()), what.data());
  std::abort();
}

// The graph loader and validator catch any yaml-cpp exception that escapes their readers as a
// last resort (a diagnostic "cannot read the graph: ..." or "cannot validate the graph: ...",
// graph.cpp, validate.cpp), so `dyad validate` never aborts. For a fuzzer that is still a finding:
// the path deserves its own message at its key.
inline bool IsLoaderFallback(std::string_view message) {
  return message.rfind("cannot read the graph: ", 0) == 0 || message.rfind("cannot validate the graph: ", 0) == 0;
}

// A file of this process holding `bytes` (readers take paths). Same path on every call, so a long
// run does not litter the temporary folder.
inline std::string WriteTemp(const uint8_t* data, size_t size, const std::string& name) {
  const char* tmp = std::getenv("TMPDIR");
  const std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/dyad_fuzz_" + std::to_string(getpid()) + "_" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

// The bytes of a checked file (model, observer: magic, version, JSON header, payload, CRC32 of
// everything before it) with a correct CRC, so that the fuzzer reaches the parsers behind the
// checksum (it cannot forge a CRC32). The first input byte chooses: odd = fix the CRC, even =
// leave the bytes as they are; the rest is the file.
std::string CheckedFileBytes(const uint8_t* data, size_t size);

// Splits `text` at every occurrence of `sep` (the multi-file targets pack several files in one
// input this way).
inline std::vector<std::string_view> Split(std::string_view text, std::string_view sep) {
  std::vector<std::string_view> parts;
  size_t start = 0;
  while (true) {
    const size_t at = text.find(sep, start);
    if (at == std::string_view::npos) break;
    parts.push_back(text.substr(start, at - start));
    start = at + sep.size();
  }
  parts.push_back(text.substr(start));
  return parts;
}

}  // namespace dyad::fuzz
