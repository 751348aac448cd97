// What the NRL harnesses share (nrl_er_harness.cpp, nrl_train_harness.cpp; built by
// bench/pvrnn/nrl_reference.sh against an NRL checkout, not by dyad's CMake):
//   Expose<Tag, &Class::member>  read access to NRL's private members without editing NRL: an
//                                explicit instantiation may name a private member (C++
//                                [temp.explicit]), and the friend it defines returns the
//                                pointer-to-member; `obj->*Get(Tag())` reads it
//   ModelOf                      LibNRL's model (instantiated here: include this header once per
//                                program)
//   Fail(message)                "<kHarness>: message" on stderr, exit 2; each harness defines
//                                kHarness, its name, in its unnamed namespace
// All of it is in the unnamed namespace (one per program, as the explicit instantiations
// of Expose in each harness need: they must stand in the namespace of the template).
#pragma once

#include <cstdlib>
#include <iostream>
#include <string>

#include "lib/LibNRL.h"

namespace {

template <typename Tag, typename Tag::type M>
struct Expose {
  friend typename Tag::type Get(Tag) { return M; }
};
struct ModelOf {
  using type = oist::INetwork* oist::LibNRL::*;
  friend type Get(ModelOf);
};
template struct Expose<ModelOf, &oist::LibNRL::model>;

extern const char kHarness[];

[[noreturn]] inline void Fail(const std::string& msg) {
  std::cerr << kHarness << ": " << msg << "\n";
  std::exit(2);
}

}  // namespace
