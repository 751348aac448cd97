// The observer file: round trip and clear errors on damaged files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dyad/observer/observer_file.hpp"
#include "edit_checked_file.hpp"

namespace dyad::observer {
namespace {

std::string Temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("dyad_observer_file_" + name)).string();
}

ObserverFile Sample() {
  ClassifierSpec s;
  s.window = 4;
  s.hidden = {8, 6};
  s.classes = 3;
  s.input = InputRepresentation::kDisplacements;
  s.workspace = {{-40, 60}, {-50, 50}};
  ObserverFile f;
  f.classifier = Classifier::Create(s, 2).value();
  f.provenance.source = "test";
  f.provenance.model = "m.dpvrnn";
  f.provenance.train_seeds = {1, 2};
  f.provenance.validation_seeds = {101};
  f.provenance.steps = 200;
  f.provenance.drop = 20;
  f.provenance.epochs = 7;
  f.provenance.validation_min_diagonal = 0.97;
  return f;
}

std::string ReadAll(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void WriteAll(const std::string& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

TEST(ObserverFile, RoundTripsSpecParametersAndProvenance) {
  const std::string p = Temp("ok.dobs");
  const ObserverFile f = Sample();
  ASSERT_TRUE(SaveObserver(f, p).ok());
  auto g = LoadObserver(p);
  ASSERT_TRUE(g.ok()) << g.status().message();
  EXPECT_EQ(g->classifier.spec(), f.classifier.spec());
  EXPECT_EQ(g->classifier.parameters(), f.classifier.parameters());
  EXPECT_EQ(g->provenance.train_seeds, f.provenance.train_seeds);
  EXPECT_EQ(g->provenance.validation_min_diagonal, 0.97);
  EXPECT_TRUE(std::isnan(g->provenance.validation_accuracy));
  EXPECT_FALSE(std::filesystem::exists(p + ".tmp"));
}

TEST(ObserverFile, DamagedFilesGiveErrorsNamingTheFileAndFault) {
  const std::string p = Temp("good.dobs"), bad = Temp("bad.dobs");
  ASSERT_TRUE(SaveObserver(Sample(), p).ok());
  const std::string good = ReadAll(p);
  auto message = [&](const std::string& bytes) {
    WriteAll(bad, bytes);
    auto r = LoadObserver(bad);
    return r.ok() ? std::string("OK") : r.status().message();
  };
  // Truncated anywhere: within the magic, the fixed header, the JSON, the payload, the CRC.
  for (size_t n : {size_t{0}, size_t{5}, size_t{12}, size_t{30}, good.size() / 2, good.size() - 9, good.size() - 1}) {
    const std::string m = message(good.substr(0, n));
    EXPECT_EQ(m.rfind(bad + ": ", 0), 0u) << n << ": " << m;
    EXPECT_TRUE(m.find("truncated") != std::string::npos || m.find("bad magic") != std::string::npos ||
                m.find("checksum") != std::string::npos)
        << n << ": " << m;
  }
  std::string flipped = good;
  flipped[good.size() - 20] ^= 0x40;
  EXPECT_EQ(message(flipped), bad + ": corrupted or truncated (checksum mismatch)");
  std::string magic = good;
  magic[0] = 'X';
  EXPECT_EQ(message(magic), bad + ": not a dyad observer file (bad magic)");
  std::string version = good;
  version[8] = 9;
  EXPECT_EQ(message(version), bad + ": format version 9, this build reads version 1");
  EXPECT_EQ(LoadObserver(Temp("missing.dobs")).status().message(), Temp("missing.dobs") + ": cannot open");
}

// nlohmann's get<int>() of 1e30 is undefined behaviour and of 4294967297 wraps to 1 (the file then
// loaded): whole-number header fields are read exactly (pvrnn/json_fields.hpp).
TEST(ObserverFile, HeaderNumbersOutOfRangeAreDataLossNotConvertedOrWrapped) {
  const std::string p = Temp("range.dobs");
  ASSERT_TRUE(SaveObserver(Sample(), p).ok());
  const std::string good = ReadAll(p);
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> cases = {
      {[](nlohmann::json& h) { h["spec"]["window"] = 1e30; }, "window = 1e+30: not a whole number in -2147483648..2147483647"},
      {[](nlohmann::json& h) { h["spec"]["window"] = 4294967300u; }, "window = 4294967300: not a whole number in -2147483648..2147483647"},
      {[](nlohmann::json& h) { h["spec"]["hidden"][1] = 4294967302u; }, "hidden[1] = 4294967302: not a whole number in -2147483648..2147483647"},
      {[](nlohmann::json& h) { h["provenance"]["train_seeds"][0] = -1; }, "train_seeds[0] = -1: not a whole number in 0..18446744073709551615"},
  };
  for (const auto& [edit, message] : cases) {
    pvrnn::testing::WriteWithEditedHeader(good, kObserverFileVersion, p, edit);
    auto r = LoadObserver(p);
    ASSERT_FALSE(r.ok()) << message;
    EXPECT_EQ(r.status().code(), Status::Code::kDataLoss);
    EXPECT_EQ(r.status().message(), p + ": unreadable header: " + message);
  }
}

}  // namespace
}  // namespace dyad::observer
