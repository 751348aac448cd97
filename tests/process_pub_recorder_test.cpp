// `dyad pub --graph` waits for every reader the graph declares for the topic, its recorder too
// (dyad/topic_readers.hpp): a graph whose only reader of the topic is its recorder records every
// sample published into it, however the readers of the topic come and go.
#include "process_fixture.hpp"

#include <signal.h>

#include <set>

namespace dyad::testing {
namespace {

// 20 pubs, each a new participant with one sample. The first is started before the graph, while
// `dyad echo` (a reader outside the graph) already listens: waiting for "any reader" published it
// to echo alone and the recording lost it; waiting for the graph's recorder, it is recorded.
TEST_F(ProcessTest, PubIntoARecorderOnlyGraphIsRecordedEveryTime) {
  const std::string domain = std::to_string(domain_);
  const fs::path rec = dir_ / "rec.mcap";
  const fs::path g = Write("g.yaml", "graph: pubrec\ndomain_id: " + domain +
                                         "\ntopics:\n  count: {type: Counter, depth: 8}\n"
                                         "components:\n"
                                         "  rec: {type: recorder, rate_hz: 10, params: {file: " + rec.string() + ", topics: [count]}}\n");
  constexpr int kPubs = 20;
  auto pub = [&](int i) {
    return Dyad({"pub", "count", "{value: " + std::to_string(i) + "}", "--graph", g.string(), "--wait", "30"});
  };
  Child echo(Dyad({"echo", "count", "--graph", g.string(), "-n", "1", "--duration", "60"}), dir_, "echo");
  Child first(pub(0), dir_, "pub0");
  std::this_thread::sleep_for(std::chrono::seconds(2));  // pub finds echo's reader first
  Child run(Dyad({"run", g.string(), "--duration", "120", "--quiet"}), dir_, "run");
  ASSERT_EQ(first.Wait(60), 0) << first.err();
  EXPECT_EQ(first.err(), "");
  for (int i = 1; i < kPubs; ++i) {
    Child p(pub(i), dir_, "pub" + std::to_string(i));
    ASSERT_EQ(p.Wait(60), 0) << p.err();
    EXPECT_EQ(p.err(), "") << i;  // no "publishing anyway"
  }
  EXPECT_EQ(echo.Wait(60), 0) << echo.err();
  run.Signal(SIGINT);
  ASSERT_EQ(run.Wait(30), 130) << run.err();
  Child csv(Dyad({"bag", "export", rec.string(), "--csv", (dir_ / "csv").string()}), dir_, "csv");
  ASSERT_EQ(csv.Wait(60), 0) << csv.err();
  std::istringstream lines(ReadFile(dir_ / "csv" / "count.csv"));
  std::string header, line;
  ASSERT_TRUE(std::getline(lines, header));
  std::vector<std::string> columns;
  for (std::istringstream h(header); std::getline(h, line, ',');) columns.push_back(line);
  const size_t value = std::find(columns.begin(), columns.end(), "value") - columns.begin();
  ASSERT_LT(value, columns.size()) << header;
  std::multiset<int> values;
  while (std::getline(lines, line)) {
    std::vector<std::string> fields;
    for (std::istringstream row(line); std::getline(row, header, ',');) fields.push_back(header);
    ASSERT_LT(value, fields.size()) << line;
    values.insert(std::stoi(fields[value]));
  }
  std::multiset<int> expected;
  for (int i = 0; i < kPubs; ++i) expected.insert(i);
  EXPECT_EQ(values, expected) << ReadFile(dir_ / "csv" / "count.csv");
}

}  // namespace
}  // namespace dyad::testing
