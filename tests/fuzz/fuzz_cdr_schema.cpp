// Fuzz target: the IDL schema parser of the CDR decoder (schemas come from recordings and peers).
// A schema that parses is also compiled for decoding: its structs' columns are listed and a small
// fixed payload is decoded against each (bounded work whatever the IDL says).
#include <cctype>
#include <string>
#include <vector>

#include "dyad/cdr_decoder.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string idl(reinterpret_cast<const char*>(data), size);
  dyad::StatusOr<dyad::cdr::Schema> parsed = dyad::cdr::Schema::Parse(idl);
  if (!parsed.ok()) {
    const dyad::Status& s = parsed.status();
    dyad::fuzz::Require(s.message().rfind("line ", 0) == 0, "schema error without its line: " + s.message());
    dyad::fuzz::Require(s.code() == dyad::Status::Code::kInvalidArgument || s.code() == dyad::Status::Code::kUnimplemented,
                        "schema error with an unexpected code: " + s.ToString());
    return 0;
  }
  const dyad::cdr::Schema& schema = *parsed;
  // Struct names are not exposed: try the identifiers written after `struct`, with their module.
  static const uint8_t payload[] = {0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 'a', 0, 0, 0,
                                    3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xf0, 0x3f, 1, 2, 3, 4};
  size_t at = 0;
  int budget = 8;
  while (budget-- > 0 && (at = idl.find("struct ", at)) != std::string::npos) {
    at += 7;
    size_t end = at;
    while (end < idl.size() && (std::isalnum(static_cast<unsigned char>(idl[end])) || idl[end] == '_')) ++end;
    const std::string name = idl.substr(at, end - at);
    if (name.empty()) continue;
    for (const std::string& candidate : {name, "m::" + name}) {
      if (!schema.HasType(candidate)) continue;
      (void)dyad::cdr::Columns(schema, candidate);
      std::vector<dyad::cdr::Field> fields;
      if (dyad::cdr::Decode(schema, candidate, payload, sizeof payload, &fields).ok()) (void)dyad::cdr::ToJson(fields);
      std::vector<std::string> row;
      (void)dyad::cdr::DecodeRow(schema, candidate, payload, sizeof payload, &row);
    }
  }
  return 0;
}
