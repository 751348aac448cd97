#include "dyad/pvrnn/model_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "edit_checked_file.hpp"
#include "test_paths.hpp"

namespace dyad::pvrnn {
namespace {

std::string ReadAll(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}
void WriteAll(const std::string& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

Model SmallModel() {
  ModelSpec spec = ModelSpec::MacawBot();
  spec.layers[0].d = 6;
  spec.layers[1].d = 3;
  Model m = Model::Initialize(spec, 5, 2, 42);
  m.provenance = {"test", "somewhere/Macaw", 123, 42, "float", 0.5, 0.25, 0.125};
  return m;
}

TEST(ModelFile, RoundTripsEverything) {
  const std::string path = testing::TempPath("roundtrip.dpvrnn");
  Model m = SmallModel();
  TrainingState st;
  st.adam_step = 7;
  st.weights_m = Eigen::VectorXd::Random(m.weights.flat().size());
  st.weights_v = Eigen::VectorXd::Random(m.weights.flat().size());
  st.adaptive_m = Eigen::VectorXd::Random(m.adaptive.flat().size());
  st.adaptive_v = Eigen::VectorXd::Random(m.adaptive.flat().size());
  st.rng_state = "1 2 3";
  m.training = st;
  ASSERT_TRUE(SaveModel(m, path).ok());
  auto back = LoadModel(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->spec, m.spec);
  EXPECT_EQ(back->weights.flat(), m.weights.flat());
  EXPECT_EQ(back->adaptive.flat(), m.adaptive.flat());
  EXPECT_EQ(back->provenance.dataset, "somewhere/Macaw");
  EXPECT_EQ(back->provenance.epochs, 123);
  EXPECT_EQ(back->provenance.final_loss, 0.5);
  ASSERT_TRUE(back->training.has_value());
  EXPECT_EQ(back->training->adam_step, 7);
  EXPECT_EQ(back->training->weights_v, st.weights_v);
  EXPECT_EQ(back->training->rng_state, "1 2 3");
  std::filesystem::remove(path);
}

// What `dyad train` writes as its output: no optimiser state.
TEST(ModelFile, RoundTripsAModelWithoutTrainingState) {
  const std::string path = testing::TempPath("plain.dpvrnn");
  const Model m = SmallModel();
  ASSERT_TRUE(SaveModel(m, path).ok());
  auto back = LoadModel(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->weights.flat(), m.weights.flat());
  EXPECT_EQ(back->adaptive.flat(), m.adaptive.flat());
  EXPECT_FALSE(back->training.has_value());
  std::filesystem::remove(path);
}

TEST(ModelFile, MissingFileNamesThePath) {
  auto r = LoadModel("/nonexistent/x.dpvrnn");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "/nonexistent/x.dpvrnn: cannot open");
}

TEST(ModelFile, EveryTruncationIsAnErrorNeverACrash) {
  const std::string path = testing::TempPath("trunc.dpvrnn");
  ASSERT_TRUE(SaveModel(SmallModel(), path).ok());
  const std::string full = ReadAll(path);
  for (size_t n : {size_t(0), size_t(5), size_t(8), size_t(20), size_t(30), full.size() / 2, full.size() - 9,
                   full.size() - 1}) {
    WriteAll(path, full.substr(0, n));
    auto r = LoadModel(path);
    ASSERT_FALSE(r.ok()) << "cut at " << n;
    EXPECT_EQ(r.status().message().rfind(path + ": ", 0), 0u) << r.status().message();
  }
  WriteAll(path, full.substr(0, full.size() / 2));
  EXPECT_NE(LoadModel(path).status().message().find("truncated"), std::string::npos) << LoadModel(path).status().message();
  std::filesystem::remove(path);
}

TEST(ModelFile, FlippedByteIsReportedAsCorrupted) {
  const std::string path = testing::TempPath("flip.dpvrnn");
  ASSERT_TRUE(SaveModel(SmallModel(), path).ok());
  std::string bytes = ReadAll(path);
  for (size_t at : {size_t(40), bytes.size() / 2, bytes.size() - 20}) {
    std::string bad = bytes;
    bad[at] ^= 0x10;
    WriteAll(path, bad);
    auto r = LoadModel(path);
    ASSERT_FALSE(r.ok()) << "flip at " << at;
    EXPECT_NE(r.status().message().find(path + ": "), std::string::npos);
  }
  std::string bad = bytes;
  bad[bytes.size() / 2] ^= 0x01;  // inside the payload: only the checksum can tell
  WriteAll(path, bad);
  EXPECT_EQ(LoadModel(path).status().message(), path + ": corrupted (checksum mismatch)");
  std::filesystem::remove(path);
}

TEST(ModelFile, WrongVersionIsReportedWithBothVersions) {
  const std::string path = testing::TempPath("version.dpvrnn");
  ASSERT_TRUE(SaveModel(SmallModel(), path).ok());
  std::string bytes = ReadAll(path);
  bytes[8] = 9;
  WriteAll(path, bytes);
  auto r = LoadModel(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), path + ": format version 9, this build reads version 1");
  std::filesystem::remove(path);
}

// Found reviewing the length checks for the fuzz target (input in tests/fuzz/regressions/
// model_file; the fuzzer itself did not reach it in short runs): a tensor entry with a huge offset
// made the sum of offsets wrap around to exactly the payload size, so a real tensor placed past
// the end of the file was read out of bounds. Every extent is now checked on its own.
TEST(ModelFile, TensorOffsetsThatWrapAroundAreDataLossNotAnOutOfBoundsRead) {
  const std::string path = testing::TempPath("wrap.dpvrnn");
  ASSERT_TRUE(SaveModel(SmallModel(), path).ok());
  const std::string good = ReadAll(path);
  testing::WriteWithEditedHeader(good, kModelFileVersion, path, [](nlohmann::json& h) {
    uint64_t payload_values = 0;
    for (const auto& t : h["tensors"])
      payload_values = std::max<uint64_t>(payload_values, t["offset"].get<uint64_t>() + t["rows"].get<uint64_t>() * t["cols"].get<uint64_t>());
    h["tensors"][0]["offset"] = payload_values;  // the first weights start where the file ends
    // (1 << 61) + payload_values: times 8 bytes, that wraps to exactly the payload size.
    h["tensors"].push_back({{"name", "pad"}, {"rows", 0}, {"cols", 0}, {"offset", (uint64_t{1} << 61) + payload_values}});
  });
  auto r = LoadModel(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), Status::Code::kDataLoss);
  EXPECT_EQ(r.status().message().rfind(path + ": truncated: tensor ", 0), 0u) << r.status().message();
  EXPECT_NE(r.status().message().find(") does not fit in the payload of "), std::string::npos) << r.status().message();
  std::filesystem::remove(path);
}

// Found by UBSan on a hand-made input while the fuzz target was written: nlohmann's get<int>()
// of 1e30 is undefined behaviour, and of 4294967301 silently wraps to 5 (the file then loaded).
// Whole-number header fields are now read exactly (json_fields.hpp).
TEST(ModelFile, HeaderNumbersOutOfRangeAreDataLossNotConvertedOrWrapped) {
  const std::string path = testing::TempPath("range.dpvrnn");
  ASSERT_TRUE(SaveModel(SmallModel(), path).ok());
  const std::string good = ReadAll(path);
  struct Case {
    std::function<void(nlohmann::json&)> edit;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](nlohmann::json& h) { h["spec"]["layers"][0]["d"] = 1e30; }, "d = 1e+30: not a whole number in -2147483648..2147483647"},
      {[](nlohmann::json& h) { h["steps"] = 4294967301u; }, "steps = 4294967301: not a whole number in -2147483648..2147483647"},
      {[](nlohmann::json& h) { h["tensors"][0]["rows"] = -6; }, "rows = -6: not a whole number in 0..18446744073709551615"},
      {[](nlohmann::json& h) { h["provenance"]["seed"] = 2.5; }, "seed = 2.5: not a whole number in 0..18446744073709551615"},
  };
  for (const Case& c : cases) {
    testing::WriteWithEditedHeader(good, kModelFileVersion, path, c.edit);
    auto r = LoadModel(path);
    ASSERT_FALSE(r.ok()) << c.message;
    EXPECT_EQ(r.status().code(), Status::Code::kDataLoss);
    EXPECT_EQ(r.status().message(), path + ": malformed header: " + c.message);
  }
  std::filesystem::remove(path);
}

TEST(ModelFile, OtherFileIsNotAModel) {
  const std::string path = testing::TempPath("other.dpvrnn");
  WriteAll(path, "d=40,10\nz=4,1\n");
  EXPECT_EQ(LoadModel(path).status().message(), path + ": not a dyad PV-RNN model file (bad magic)");
  std::filesystem::remove(path);
}

TEST(ModelSpec, DefaultShapeIsValid) { EXPECT_TRUE(ModelSpec::MacawBot().Validate().ok()); }

// Sizes are ints in the engine: a model too large to index is refused, not overflowed.
TEST(ModelSpec, RefusesAModelWithTooManyWeights) {
  ModelSpec spec = ModelSpec::MacawBot();
  spec.layers[0].d = 100000;
  EXPECT_EQ(spec.Validate().message(), "layers: the model would have 10006600400 weights, more than 100000000");
}

}  // namespace
}  // namespace dyad::pvrnn
