// The fixture the online study's unit tests share: a study of two participants (P01, P02) and two
// conditions in a fresh folder of its own per test (`dir_`, named after `prefix` and the test),
// with a reconnect window of 5 s and a consent text; the folder is kept when the test failed.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <utility>

#include "study_file.hpp"

namespace dyad::study::testing {

class OnlineStudyTest : public ::testing::Test {
 protected:
  explicit OnlineStudyTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + std::to_string(getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    study_.name = "gain";
    study_.file = (dir_ / "s.yaml").string();
    study_.data = (dir_ / "gain-data").string();
    study_.participants = {"P01", "P02"};
    study_.conditions = {Condition{"low", "A", {"src.start=1"}, {}}, Condition{"high", "B", {"src.start=3"}, {}}};
    study_.online.reconnect_s = 5;
    study_.online.consent_text = "Do you agree?";
  }
  void TearDown() override {
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }
  std::string prefix_;
  std::filesystem::path dir_;
  Study study_;
};

}  // namespace dyad::study::testing
