#include "fuzz_catalog.hpp"

#include "fuzz_support.hpp"

namespace dyad::fuzz {

const Catalog& BuiltinCatalog() {
  static const Catalog* catalog = [] {
    auto* c = new Catalog();  // never deleted: harnesses run until the process ends
    const Status s = c->LoadDefault({});
    Require(s.ok() && c->Find("human_synthetic") != nullptr, "built-in plugins: " + s.ToString());
    return c;
  }();
  return *catalog;
}

}  // namespace dyad::fuzz
