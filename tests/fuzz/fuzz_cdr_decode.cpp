// Fuzz target: the IDL-driven CDR decoder (`dyad echo`, bag export, recorder) against every
// message type of idl/, and the decoder test's dyad_cdr_test::Everything (every supported IDL
// construct): schema fixed, bytes fuzzed. The first byte picks the type (in that order); the rest
// is the serialized sample (encapsulation header first). Decode, ToJson, Columns and DecodeRow
// all run.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <dyad/msg/types.hpp>

#include "dyad/cdr_decoder.hpp"
#include "fuzz_support.hpp"

namespace {

struct Type {
  dyad::cdr::Schema schema;
  std::string name;
};

const std::vector<Type>& Types() {
  static const std::vector<Type> types = [] {
    std::vector<Type> out;
    for (const dyad::TypeInfo* info : dyad::msg::AllTypes()) {
      dyad::StatusOr<dyad::cdr::Schema> schema = dyad::cdr::Schema::Parse(info->idl);
      dyad::fuzz::Require(schema.ok(), "IDL of " + info->name + ": " + schema.status().message());
      dyad::fuzz::Require(schema->HasType(info->name), info->name + " not in its schema");
      out.push_back({*schema, info->name});
    }
    std::ifstream in(DYAD_CDR_TEST_IDL);
    std::stringstream idl;
    idl << in.rdbuf();
    dyad::StatusOr<dyad::cdr::Schema> everything = dyad::cdr::Schema::Parse(idl.str());
    dyad::fuzz::Require(everything.ok() && everything->HasType("dyad_cdr_test::Everything"),
                        DYAD_CDR_TEST_IDL ": " + everything.status().message());
    out.push_back({*everything, "dyad_cdr_test::Everything"});
    return out;
  }();
  return types;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const Type& type = Types()[data[0] % Types().size()];
  std::vector<dyad::cdr::Field> fields;
  // A payload is the only thing fuzzed here: every failure is a damaged payload (DataLoss) or an
  // encapsulation we do not read (Unimplemented), with a message.
  const auto expected_failure = [](const dyad::Status& s) {
    return !s.message().empty() &&
           (s.code() == dyad::Status::Code::kDataLoss || s.code() == dyad::Status::Code::kUnimplemented);
  };
  const dyad::Status decoded = dyad::cdr::Decode(type.schema, type.name, data + 1, size - 1, &fields);
  if (decoded.ok()) {
    (void)dyad::cdr::ToJson(fields);
  } else {
    dyad::fuzz::Require(expected_failure(decoded), "Decode: unexpected failure " + decoded.ToString());
  }
  const std::vector<std::string> columns = dyad::cdr::Columns(type.schema, type.name);
  std::vector<std::string> row;
  const dyad::Status row_decoded = dyad::cdr::DecodeRow(type.schema, type.name, data + 1, size - 1, &row);
  if (row_decoded.ok()) {
    dyad::fuzz::Require(row.size() == columns.size(), "DecodeRow: row and columns differ in size");
  } else {
    dyad::fuzz::Require(expected_failure(row_decoded), "DecodeRow: unexpected failure " + row_decoded.ToString());
  }
  return 0;
}
