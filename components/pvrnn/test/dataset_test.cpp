#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "test_paths.hpp"

namespace dyad::pvrnn {
namespace {

TEST(Dataset, ReadsTheMacawSet) {
  DYAD_REQUIRE_VCBOT();
  auto d = LoadNrlDataset(testing::VcbotDir() + "/dataset/Macaw");
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->size(), 7);
  EXPECT_EQ(d->steps(), 72);
  EXPECT_EQ(d->dofs(), 2);
  EXPECT_NEAR(d->sequences[0](0, 0), -2.5558292687809034, 1e-12);
}

TEST(AnalyticDataset, SevenClosedPrimitivesInsideTheWorkspace) {
  const Dataset d = MakeAnalyticDataset();
  ASSERT_EQ(d.size(), 7);
  EXPECT_EQ(d.names, (std::vector<std::string>{"circle", "square", "triangle", "figure eight", "star", "heart", "trefoil"}));
  for (const auto& s : d.sequences) {
    ASSERT_EQ(s.rows(), 2);
    ASSERT_EQ(s.cols(), 72);
    EXPECT_LE(s.cwiseAbs().maxCoeff(), 50.0);
    // Closed: the step from the last point back to the first is no longer than the longest step.
    double longest = 0;
    for (int t = 1; t < 72; ++t) longest = std::max(longest, (s.col(t) - s.col(t - 1)).norm());
    EXPECT_LE((s.col(0) - s.col(71)).norm(), longest + 1e-9);
  }
}

TEST(Dataset, RepeatSequencesTilesEachPrimitive) {
  const Dataset d = MakeAnalyticDataset();
  const Dataset r = RepeatSequences(d, 3);
  ASSERT_EQ(r.size(), d.size());
  ASSERT_EQ(r.steps(), 3 * d.steps());
  for (int i = 0; i < d.size(); ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(r.sequences[i].middleCols(k * d.steps(), d.steps()), d.sequences[i]);
  }
}

TEST(Dataset, WrittenAnalyticSetReadsBackIdentically) {
  const Dataset d = MakeAnalyticDataset();
  const std::string dir = testing::TempPath("analytic_set");
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(WriteNrlDataset(d, dir).ok());
  auto back = LoadNrlDataset(dir);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->size(), 7);
  for (int p = 0; p < 7; ++p) EXPECT_EQ(back->sequences[p], d.sequences[p]);
  EXPECT_EQ(back->names, d.names);
  EXPECT_EQ(back->names.at(5), "heart");
  // A set without names (NRL's, a person's demonstrations) reads back without, and writing it
  // over a named one removes the old names.
  Dataset unnamed = d;
  unnamed.names.clear();
  ASSERT_TRUE(WriteNrlDataset(unnamed, dir).ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/names.txt"));
  back = LoadNrlDataset(dir);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(back->names.empty());
  std::filesystem::remove_all(dir);
}

// names.txt: exactly one printable name of 1..40 bytes per primitive, none twice; else an error
// naming the file and line. A CRLF file and a last empty line are fine.
TEST(Dataset, BadNamesAreReportedAtTheirLine) {
  const std::string dir = testing::TempPath("named_set");
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(WriteNrlDataset(MakeAnalyticDataset(), dir).ok());
  const std::string file = dir + "/names.txt";
  const std::pair<std::string, std::string> cases[] = {
      {"a\nb\n", file + ": 2 names, dataset.d says numberprims=7"},
      {"a\nb\nc\nd\ne\nf\ng\nh\n", file + ": 8 names, dataset.d says numberprims=7"},
      {"a\nb\nc\nb\ne\nf\ng\n", file + ":4: 'b' names primitive 1 already"},
      {"a\n\nc\nd\ne\nf\ng\n", file + ":2: a name is 1 to 40 bytes, got 0"},
      {"a\nb\nc\nd\ne\nf\n" + std::string(41, 'x') + "\n", file + ":7: a name is 1 to 40 bytes, got 41"},
      {"a\nb\tc\nc\nd\ne\nf\ng\n", file + ":2: a name holds no control characters"},
  };
  for (const auto& [text, error] : cases) {
    { std::ofstream(file, std::ios::binary) << text; }
    auto d = LoadNrlDataset(dir);
    ASSERT_FALSE(d.ok()) << text;
    EXPECT_EQ(d.status().message(), error) << text;
  }
  { std::ofstream(file, std::ios::binary) << "left eye\r\nhead\r\nbeak\r\nneck\r\nright wing\r\nbelly\r\nleft wing\r\n"; }
  auto d = LoadNrlDataset(dir);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->names.front(), "left eye");
  EXPECT_EQ(d->names.back(), "left wing");
  std::filesystem::remove_all(dir);
}

TEST(Dataset, ShortPrimitiveFileIsReportedWithItsName) {
  const std::string dir = testing::TempPath("short_set");
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(WriteNrlDataset(MakeAnalyticDataset(), dir).ok());
  { std::ofstream(dir + "/primitive_3_0.csv") << "1,2\n3,4\n"; }
  auto back = LoadNrlDataset(dir);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("primitive_3_0.csv: 2 rows, dataset.d says numbertimes=72"), std::string::npos)
      << back.status().message();
  std::filesystem::remove_all(dir);
}

// NRL's own data folder (oist-cnru/NRL data/dataset, nsamples=1,3,2): no dataset.d, several
// samples per primitive. Every sample is a training sequence (6, not the 3 samples 0), in
// primitive-major order; files not read are named in a warning.
void WriteSample(const std::string& dir, int p, int s, int steps, double base) {
  std::ofstream out(dir + "/primitive_" + std::to_string(p) + "_" + std::to_string(s) + ".csv");
  for (int t = 0; t < steps; ++t) out << base + t << "," << -base - t << "\n";
}

TEST(Dataset, NrlFolderWithoutDatasetDReadsEverySample) {
  const std::string dir = testing::TempPath("nrl_samples");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const int nsamples[] = {1, 3, 2};
  for (int p = 0; p < 3; ++p)
    for (int s = 0; s < nsamples[p]; ++s) WriteSample(dir, p, s, 5, 10 * p + s);
  WriteSample(dir, 0, 2, 5, 99);  // no primitive_0_1.csv: after a gap
  WriteSample(dir, 4, 0, 5, 99);  // no primitive_3_0.csv: after a gap
  { std::ofstream(dir + "/notes.txt") << "recorded on Monday\n"; }
  auto d = LoadNrlDataset(dir);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->size(), 6);
  EXPECT_EQ(d->primitives(), 3);
  EXPECT_EQ(d->steps(), 5);
  EXPECT_EQ(d->dofs(), 2);
  EXPECT_EQ(d->SequencesPerPrimitive(), (std::vector<int>{1, 3, 2}));
  EXPECT_EQ(d->primitive, (std::vector<int>{0, 1, 1, 1, 2, 2}));
  EXPECT_EQ(d->sample, (std::vector<int>{0, 0, 1, 2, 0, 1}));
  for (int k = 0; k < 6; ++k) EXPECT_EQ(d->sequences[k](0, 0), 10 * d->primitive[k] + d->sample[k]) << k;
  EXPECT_EQ(d->sampling_period_ms, 100);
  EXPECT_EQ(d->warnings, (std::vector<std::string>{
                             dir + "/notes.txt: not used (not a file of a data set (dataset.d, names.txt, primitive_<p>_<s>.csv))",
                             dir + "/primitive_0_2.csv: not used (primitive_0_1.csv is missing: samples are read from 0 up to "
                                   "the first missing one)",
                             dir + "/primitive_4_0.csv: not used (primitive_3_0.csv is missing: primitives are read from 0 up "
                                   "to the first missing one)",
                         }));
  // A sample of another length is refused, naming both files.
  WriteSample(dir, 2, 1, 4, 0);
  auto bad = LoadNrlDataset(dir);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), dir + "/primitive_2_1.csv: 4 rows, primitive_0_0.csv has 5");
  std::filesystem::remove_all(dir);
}

// With dataset.d, the samples are read too, and a primitive beyond numberprims is warned about.
// Written back, the set reads back the same (samples, names); names.txt names primitives.
TEST(Dataset, SamplesWithDatasetDRoundTrip) {
  const std::string dir = testing::TempPath("samples_meta");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  { std::ofstream(dir + "/dataset.d") << "samplingperiod=50\nnumbertimes=4\nnumberprims=2\n"; }
  { std::ofstream(dir + "/names.txt") << "circle\nstar\n"; }
  for (int s = 0; s < 2; ++s) WriteSample(dir, 0, s, 4, s);
  WriteSample(dir, 1, 0, 4, 7);
  WriteSample(dir, 2, 0, 4, 9);
  auto d = LoadNrlDataset(dir);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->size(), 3);
  EXPECT_EQ(d->SequencesPerPrimitive(), (std::vector<int>{2, 1}));
  EXPECT_EQ(d->names, (std::vector<std::string>{"circle", "circle (sample 1)", "star"}));
  EXPECT_EQ(d->warnings, (std::vector<std::string>{dir + "/primitive_2_0.csv: not used (dataset.d says numberprims=2)"}));
  const std::string out = testing::TempPath("samples_meta_out");
  std::filesystem::remove_all(out);
  ASSERT_TRUE(WriteNrlDataset(MakeAnalyticDataset(), out).ok());  // an earlier set's files, then this one
  ASSERT_TRUE(WriteNrlDataset(*d, out).ok());
  auto back = LoadNrlDataset(out);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->primitive, d->primitive);
  EXPECT_EQ(back->sample, d->sample);
  EXPECT_EQ(back->names, d->names);
  EXPECT_EQ(back->sampling_period_ms, 50);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(back->sequences[k], d->sequences[k]);
  EXPECT_TRUE(back->warnings.empty()) << back->warnings.front();
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(out);
}

TEST(Dataset, EmptyFolderIsNotADataset) {
  const std::string dir = testing::TempPath("no_set");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  auto d = LoadNrlDataset(dir);
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find(dir + ": neither dataset.d nor primitive_0_0.csv"), std::string::npos) << d.status().message();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dyad::pvrnn
