// Paths the tests use; DYAD_SHARED_DATA_DIR comes from CMake (../shared/data by default).
#pragma once

#include <filesystem>
#include <string>

namespace dyad::pvrnn::testing {

inline std::string VcbotDir() { return std::string(DYAD_SHARED_DATA_DIR) + "/vcbot"; }
inline bool HaveVcbot() { return std::filesystem::exists(VcbotDir() + "/model/MacawBot"); }
inline std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("dyad_pvrnn_test_" + name)).string();
}

}  // namespace dyad::pvrnn::testing

#define DYAD_REQUIRE_VCBOT()                                                                    \
  do {                                                                                          \
    if (!::dyad::pvrnn::testing::HaveVcbot())                                                   \
      GTEST_SKIP() << "needs ../shared/data/vcbot (not found at " << ::dyad::pvrnn::testing::VcbotDir() \
                   << ")";                                                                      \
  } while (0)
