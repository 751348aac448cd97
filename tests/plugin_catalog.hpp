// The catalog of the plugins this build made (DYAD_TEST_PLUGIN_DIR: examples, the study's
// components), loaded once per test binary: what graph tests validate against.
#pragma once

#include <gtest/gtest.h>

#include <dyad/catalog.hpp>

namespace dyad::testing {

inline const Catalog& BuiltPlugins() {
  static const Catalog* catalog = [] {
    auto* c = new Catalog();
    const Status s = c->Load(DYAD_TEST_PLUGIN_DIR);
    EXPECT_TRUE(s.ok()) << s.ToString();
    return c;
  }();
  return *catalog;
}

}  // namespace dyad::testing
