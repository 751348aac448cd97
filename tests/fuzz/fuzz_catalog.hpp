// The catalog of this build's built-in plugins, for the graph harnesses of tests/fuzz
// (fuzz_graph, fuzz_set_override, fuzz_graph_chain), which validate what they load against it as
// `dyad validate` does. Loaded once, on the first call, and kept for the process (libFuzzer calls
// a harness millions of times); a build whose plugins cannot be loaded aborts at that first call
// with the reason (Require), since every input would then be rejected for the same wrong reason.
#pragma once

#include "dyad/catalog.hpp"

namespace dyad::fuzz {

const Catalog& BuiltinCatalog();

}  // namespace dyad::fuzz
