// Reference documentation generated from the code, so it cannot drift from it:
//   - a component type's ports and parameters, from its Describe() (docs/components.md embeds one
//     block per built-in type);
//   - every message type and its fields, from the IDL text each type carries (docs/messages.md).
// `dyad types --markdown` and `dyad types --messages --markdown` print them; tools/docs.py
// splices them into docs/ and, with --check, fails when the committed docs differ (a CTest).
//
// Output is deterministic: it depends only on the specs and the IDL, never on paths or time.
#pragma once

#include <string>

#include <dyad/catalog.hpp>

namespace dyad::cli {

// One component type, between marker comments naming it:
//   <!-- BEGIN dyad types --markdown NAME ... -->
//   summary, a ports table, a params table
//   <!-- END dyad types --markdown NAME -->
std::string ComponentReferenceMarkdown(const std::string& name, const CatalogEntry& entry);

// Every message type of the catalog (built-in IDL and loaded plugins' ports), one section each:
// its IDL name, the comment above its definition, and a table of its members (name, IDL type,
// the comment at the end of the member's line).
std::string MessageReferenceMarkdown(const Catalog& catalog);

// A parameter's bounds exactly: integers as integers ("1024..1073741824", not "1.07374e+09"),
// other numbers in the shortest form that reads back to the same double; "-inf"/"inf" if unset.
std::string ParamRangeText(const ParamSpec& p);

}  // namespace dyad::cli
