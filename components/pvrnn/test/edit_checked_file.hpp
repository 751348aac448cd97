// Test helper: a checked file (model, observer) whose JSON header was edited and whose checksum
// was then made right again, what a careless tool or an attacker can write. Test code only; the
// model and observer tests share it.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "dyad/pvrnn/checked_file.hpp"

namespace dyad::pvrnn::testing {

// Writes `good` (a valid checked file of `version`) with its header passed through `edit` to
// `path`; returns the new bytes. Magic, version and payload are kept.
inline std::string WriteWithEditedHeader(const std::string& good, uint32_t version, const std::string& path,
                                         const std::function<void(nlohmann::json&)>& edit) {
  char magic[8];
  std::memcpy(magic, good.data(), 8);
  auto view = OpenCheckedFile(good, path, magic, version, "checked file");
  EXPECT_TRUE(view.ok()) << view.status().message();
  if (!view.ok()) return {};
  nlohmann::json header = nlohmann::json::parse(view->json);
  edit(header);
  std::string out = BeginCheckedFile(magic, version, header.dump());
  out.append(good, view->payload_at, view->payload_bytes);
  EXPECT_TRUE(FinishCheckedFile(out, path).ok());
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace dyad::pvrnn::testing
