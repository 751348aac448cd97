// The deliberator component: configured through a fake Context (params, ports), and run in a
// stepped graph by the real `dyad` executable with test components around it.
#include "deliberator.hpp"

#include <gtest/gtest.h>

#include "dyad/testing/csv.hpp"
#include "dyad/testing/dds_domain.hpp"
#include "dyad/testing/fake_context.hpp"
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "dyad/pvrnn/model_file.hpp"

namespace fs = std::filesystem;

namespace dyad::deliberator {
namespace {

// The shared fake Context (tests/support) with the deliberator's ports bound: `reader` feeds
// `executed`, `writer` keeps every published intention.
class FakeContext {
 public:
  explicit FakeContext(std::map<std::string, ParamValue> params)
      : ctx(&Deliberator::Describe, std::move(params), 7),
        reader(ctx.Feed<msg::CartesianState>("executed")),
        writer(ctx.Capture<msg::Intention>("intention")),
        logger(ctx.log_),
        stepped_clock(ctx.stepped_clock) {}
  operator Context&() { return ctx; }
  void Poll() { ctx.PollInputs(); }

  dyad::testing::FakeContext ctx;
  dyad::testing::QueueReader<msg::CartesianState>& reader;
  dyad::testing::CapturingWriter<msg::Intention>& writer;
  dyad::testing::NullLogger& logger;
  bool& stepped_clock;
};

// A random MacawBot-shaped model file (no data needed).
std::string RandomModelFile() {
  static const std::string path = [] {
    const std::string p = (fs::temp_directory_path() / ("dyad_deliberator_test_" + std::to_string(getpid()) + ".dpvrnn")).string();
    EXPECT_TRUE(pvrnn::SaveModel(pvrnn::Model::Initialize(pvrnn::ModelSpec::MacawBot(), 72, 7, 3), p).ok());
    return p;
  }();
  return path;
}

TEST(Deliberator, PublishesAnIntentionEveryStepWithTheWindowLoss) {
  FakeContext ctx({{"model", RandomModelFile()}, {"start_primitive", int64_t{2}}});
  Deliberator d;
  ASSERT_TRUE(d.Configure(ctx).ok());
  for (int t = 0; t < 10; ++t) {
    msg::CartesianState s;
    s.x(t);
    s.y(-t);
    if (t > 0 && t != 5) ctx.reader.queue.push_back(s);  // none at step 5: own intention used
    ctx.Poll();
    ASSERT_TRUE(d.Step(StepInfo{0, static_cast<uint64_t>(t), 100'000'000}).ok());
  }
  ASSERT_EQ(ctx.writer.samples.size(), 10u);
  EXPECT_EQ(ctx.writer.samples[0].iterations(), 0u);  // step 0: nothing executed yet
  for (size_t i = 1; i < 10; ++i) {
    const msg::Intention& r = ctx.writer.samples[i];
    EXPECT_EQ(r.iterations(), 15u);
    EXPECT_GT(r.nelbo(), 0);
    EXPECT_NEAR(r.nelbo(), r.reconstruction() / 2 + r.regulation() / 5, 1e-6 * r.nelbo());
    EXPECT_GT(r.optimisation_s(), 0);
    EXPECT_FALSE(r.deadline_missed());
    EXPECT_EQ(r.header().sequence_number(), i + 1);
  }
  EXPECT_EQ(d.steps_without_executed(), 1u);
  EXPECT_EQ(d.deadline_misses(), 0u);
}

TEST(Deliberator, ATinyBudgetPublishesOnTimeAndCountsTheMisses) {
  FakeContext ctx({{"model", RandomModelFile()}, {"time_budget_ms", 1e-6}, {"iterations", int64_t{1000}}});
  Deliberator d;
  ASSERT_TRUE(d.Configure(ctx).ok());
  for (int t = 0; t < 5; ++t) ASSERT_TRUE(d.Step(StepInfo{0, static_cast<uint64_t>(t), 100'000'000}).ok());
  ASSERT_EQ(ctx.writer.samples.size(), 5u);
  EXPECT_TRUE(ctx.writer.samples[4].deadline_missed());
  EXPECT_LE(ctx.writer.samples[4].iterations(), 1u);
  EXPECT_EQ(d.deadline_misses(), 4u);
  bool warned = false;
  for (const auto& l : ctx.logger.lines) warned |= l.find("time cap") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Under the stepped clock simulated time stands still during a step: a wall-time cap would only
// make the result depend on the machine's load (a descheduled process cuts the solve), breaking
// "same graph and seed, same recording". The iteration cap alone applies.
TEST(Deliberator, UnderTheSteppedClockTheWallBudgetDoesNotCutTheSolve) {
  FakeContext ctx({{"model", RandomModelFile()}, {"time_budget_ms", 1e-6}, {"iterations", int64_t{40}}});
  ctx.stepped_clock = true;
  Deliberator d;
  ASSERT_TRUE(d.Configure(ctx).ok());
  for (int t = 0; t < 4; ++t) ASSERT_TRUE(d.Step(StepInfo{0, static_cast<uint64_t>(t), 100'000'000}).ok());
  ASSERT_EQ(ctx.writer.samples.size(), 4u);
  for (size_t i = 1; i < 4; ++i) {
    EXPECT_EQ(ctx.writer.samples[i].iterations(), 40u);
    EXPECT_FALSE(ctx.writer.samples[i].deadline_missed());
  }
  EXPECT_EQ(d.deadline_misses(), 0u);
}

// A non-finite executed position (a controller's bad reading) is treated like a missing one.
TEST(Deliberator, ANonFiniteExecutedPositionIsTakenAsMissing) {
  FakeContext ctx({{"model", RandomModelFile()}});
  Deliberator d;
  ASSERT_TRUE(d.Configure(ctx).ok());
  for (int t = 0; t < 8; ++t) {
    msg::CartesianState s;
    s.x(t == 3 ? std::nan("") : 1.0 * t);
    s.y(0);
    if (t > 0) ctx.reader.queue.push_back(s);
    ctx.Poll();
    ASSERT_TRUE(d.Step(StepInfo{0, static_cast<uint64_t>(t), 100'000'000}).ok());
    EXPECT_TRUE(std::isfinite(ctx.writer.samples.back().x())) << "step " << t;
    EXPECT_TRUE(std::isfinite(ctx.writer.samples.back().nelbo())) << "step " << t;
  }
  EXPECT_EQ(d.steps_without_executed(), 1u);
}

TEST(Deliberator, CeresIsSelectedByParam) {
  FakeContext ctx({{"model", RandomModelFile()}, {"optimizer", std::string("ceres")},
                   {"ceres", std::string("{lbfgs_rank: 5}")}, {"preset", std::string("reference")}});
  Deliberator d;
  ASSERT_TRUE(d.Configure(ctx).ok());
  for (int t = 0; t < 3; ++t) ASSERT_TRUE(d.Step(StepInfo{0, static_cast<uint64_t>(t), 100'000'000}).ok());
  EXPECT_GE(ctx.writer.samples[2].iterations(), 1u);
}

// Preset nrl (issue 44): NRL's own error regression; it generates freely until its window holds
// W (5) executed positions, then regresses with Adam (15 iterations per step).
TEST(Deliberator, NrlPresetIsNrlsErrorRegression) {
  FakeContext ctx({{"model", RandomModelFile()}, {"preset", std::string("nrl")}});
  Deliberator d;
  ASSERT_TRUE(d.Configure(ctx).ok());
  for (int t = 0; t < 7; ++t) {
    msg::CartesianState s;
    s.x(1.0 * t);
    s.y(0);
    if (t > 0) ctx.reader.queue.push_back(s);
    ctx.Poll();
    ASSERT_TRUE(d.Step(StepInfo{0, static_cast<uint64_t>(t), 100'000'000}).ok());
  }
  EXPECT_EQ(ctx.writer.samples[3].iterations(), 0u);  // 3 executed positions: free generation
  EXPECT_GE(ctx.writer.samples[6].iterations(), 1u);  // 6 held: regressing (15 unless the time cap stops it)
  FakeContext ceres({{"model", RandomModelFile()}, {"preset", std::string("nrl")}, {"optimizer", std::string("ceres")}});
  Deliberator bad;
  const Status st = bad.Configure(ceres);
  EXPECT_NE(st.message().find("params.optimizer: the nrl engine is NRL's Adam"), std::string::npos) << st.message();
}

struct BadParam {
  std::map<std::string, ParamValue> params;
  std::string message_start;
};

TEST(Deliberator, BadParamsGiveErrorsNamingTheParam) {
  const std::string bad_file = (fs::temp_directory_path() / "dyad_deliberator_not_a_model.dpvrnn").string();
  std::ofstream(bad_file) << "not a model";
  const std::vector<BadParam> cases = {
      {{{"model", std::string("/nonexistent/m.dpvrnn")}}, "params.model: /nonexistent/m.dpvrnn"},
      {{{"model", bad_file}}, "params.model: " + bad_file},
      {{{"start_primitive", int64_t{9}}}, "params.start_primitive: 9: "},
      {{{"meta_prior", std::vector<double>{1e-5}}}, "params.meta_prior: needs one value per layer (2), got 1"},
      {{{"adam", std::string("{lr: -1}")}}, "params.adam.lr: must be finite and > 0, got -1"},
      {{{"adam", std::string("{learning_rate: 0.1}")}}, "params.adam.learning_rate: unknown key"},
      {{{"adam", std::string("{lr: fast}")}}, "params.adam.lr: must be a number"},
      {{{"ceres", std::string("[1, 2]")}}, "params.ceres: must be a map"},
      {{{"ceres", std::string("{lbfgs_rank: 0}")}}, "params.ceres.lbfgs_rank: must be in 1..100, got 0"},
      {{{"ceres", std::string("{lbfgs_rank: 2.5}")}}, "params.ceres.lbfgs_rank: must be a whole number, got 2.5"},
      {{{"ceres", std::string("{max_line_search_iterations: 1e30}")}}, "params.ceres.max_line_search_iterations: must be a whole number"},
  };
  for (const auto& c : cases) {
    std::map<std::string, ParamValue> p = c.params;
    if (!p.count("model")) p["model"] = RandomModelFile();
    FakeContext ctx(p);
    Deliberator d;
    const Status s = d.Configure(ctx);
    ASSERT_FALSE(s.ok()) << c.message_start;
    EXPECT_EQ(s.message().rfind(c.message_start, 0), 0u) << "got: " << s.message();
  }
}

// ---------------------------------------------------------------------------------------------
// The real thing: `dyad run` on a stepped graph (driver stand-in -> deliberator -> file).

TEST(Deliberator, RunsInASteppedGraphAndPublishesEveryStep) {
  const fs::path dir = fs::temp_directory_path() / ("dyad_deliberator_graph_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path out = dir / "intentions.txt", graph = dir / "g.yaml";
  std::ofstream(graph) << "graph: mind\nclock: stepped\nseed: 3\ndomain_id: " << dyad::testing::DomainForThisProcess()
                       << "\nplugins: [" << DYAD_DELIBERATOR_TEST_PLUGIN << "]\ncomponents:\n"
                       << "  driver: {type: executed_script, rate_hz: 10, outputs: {state: robot/state}}\n"
                       << "  mind:\n    type: deliberator\n    rate_hz: 10\n    params: {model: " << RandomModelFile()
                       << ", start_primitive: 1, optimizer: adam}\n"
                       << "    inputs: {executed: robot/state}\n    outputs: {intention: robot/intention}\n"
                       << "  sink: {type: intention_file, trigger: in, params: {file: " << out.string()
                       << "}, inputs: {in: robot/intention}}\n"
                       << "topics:\n  robot/state: {type: CartesianState, depth: 4}\n"
                       << "  robot/intention: {type: Intention, depth: 4}\n";
  const std::string cmd = std::string(DYAD_EXE) + " run " + graph.string() + " --steps 40 > " + (dir / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << std::ifstream(dir / "log").rdbuf();
  std::ifstream in(out);
  std::string line;
  int lines = 0, optimised = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    double x, y, nelbo;
    unsigned it;
    int missed;
    ASSERT_TRUE(s >> x >> y >> nelbo >> it >> missed) << line;
    EXPECT_TRUE(std::isfinite(x) && std::isfinite(y));
    EXPECT_EQ(missed, 0);
    optimised += it > 0;
    ++lines;
  }
  EXPECT_GE(lines, 39);
  EXPECT_GE(optimised, 38);
  fs::remove_all(dir);
}

// The first word `sha256sum` prints for `file` (an implementation independent of dyad's).
std::string Sha256sum(const fs::path& file) {
  std::string out;
  if (FILE* p = popen(("sha256sum " + file.string()).c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    pclose(p);
  }
  return out.substr(0, out.find(' '));
}

// A live `model` swaps the robot's mind mid-run: in a stepped run at the step boundary after the
// request, the same in every run; recorded (the param's answer; the model topic with each model's
// SHA-256 and first step); a broken file is refused and the model in force steers on.
TEST(Deliberator, ALiveModelIsSwappedAtAStepBoundaryRecordedAndABadOneRefused) {
  const fs::path dir = fs::temp_directory_path() / ("dyad_deliberator_swap_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path a = RandomModelFile(), b = dir / "b.dpvrnn", bad = dir / "bad.dpvrnn";
  ASSERT_TRUE(pvrnn::SaveModel(pvrnn::Model::Initialize(pvrnn::ModelSpec::MacawBot(), 72, 7, 11), b.string()).ok());
  const fs::path one = dir / "one.dpvrnn";  // a model of 1 layer: the preset's meta-prior has 2 values
  pvrnn::ModelSpec one_layer = pvrnn::ModelSpec::MacawBot();
  one_layer.layers.resize(1);
  ASSERT_TRUE(pvrnn::SaveModel(pvrnn::Model::Initialize(one_layer, 72, 7, 11), one.string()).ok());
  {  // b, truncated: its checksum cannot match
    std::ifstream in(b, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(bad, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  auto run = [&](const std::string& name, const std::string& changes) {
    const fs::path rec = dir / (name + ".mcap"), graph = dir / (name + ".yaml"), csv = dir / name;
    std::ofstream(graph) << "graph: swap\nclock: stepped\nseed: 3\ndomain_id: " << dyad::testing::DomainForThisProcess()
                         << "\nplugins: [" << DYAD_DELIBERATOR_TEST_PLUGIN << "]\ncomponents:\n"
                         << "  driver: {type: executed_script, rate_hz: 10, outputs: {state: robot/state}}\n"
                         << "  mind:\n    type: deliberator\n    rate_hz: 10\n    params: {model: " << a.string()
                         << ", start_primitive: 1}\n"
                         << "    inputs: {executed: robot/state}\n    outputs: {intention: robot/intention, model: mind/model}\n"
                         << "  script: {type: param_script, rate_hz: 10, outputs: {requests: dyad/param_requests}, params: {changes: ["
                         << changes << "]}}\n"
                         << "  rec: {type: recorder, rate_hz: 10, params: {file: " << rec.string() << "}}\n";
    const std::string cmd = std::string(DYAD_EXE) + " run " + graph.string() + " --steps 40 > " + (dir / (name + ".log")).string() +
                            " 2>&1 && " + DYAD_EXE + " bag export " + rec.string() + " --csv " + csv.string() + " >> " +
                            (dir / (name + ".log")).string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << std::ifstream(dir / (name + ".log")).rdbuf();
    return csv;
  };
  const std::string swaps = "{at_s: 2.0, set: {mind.model: " + b.string() + "}}, {at_s: 3.0, set: {mind.model: " + bad.string() +
                            "}}, {at_s: 3.5, set: {mind.model: " + one.string() + "}}";
  const fs::path first = run("first", swaps), again = run("again", swaps), none = run("none", "");

  const auto changes = dyad::testing::ReadCsv(first / "dyad_params.csv");
  ASSERT_EQ(changes.size(), 3u) << std::ifstream(first / "dyad_params.csv").rdbuf();
  EXPECT_EQ(changes[0].at("op"), "applied");
  EXPECT_EQ(changes[0].at("old_value"), "\"" + a.string() + "\"");  // YAML text
  EXPECT_EQ(changes[0].at("value"), "\"" + b.string() + "\"");
  const uint64_t swap_step = std::stoull(changes[0].at("step"));
  EXPECT_EQ(swap_step, 21u);  // asked at 2.0 s, after step 20 ran: the mind's step 21 is B's first
  EXPECT_EQ(changes[1].at("op"), "refused");
  EXPECT_NE(changes[1].at("reason").find(bad.string()), std::string::npos) << changes[1].at("reason");
  EXPECT_EQ(changes[2].at("op"), "refused");
  EXPECT_NE(changes[2].at("reason").find(one.string() + " has 1 layers; the meta_prior in force has 2 values (the preset's)"),
            std::string::npos)
      << changes[2].at("reason");

  const auto models = dyad::testing::ReadCsv(first / "mind_model.csv");
  ASSERT_EQ(models.size(), 2u) << "the model at the start and the one swap: the bad files never steered";
  EXPECT_EQ(models[0].at("path"), a.string());
  EXPECT_EQ(models[0].at("sha256"), Sha256sum(a));
  EXPECT_EQ(models[0].at("step"), "0");
  EXPECT_EQ(models[1].at("path"), b.string());
  EXPECT_EQ(models[1].at("sha256"), Sha256sum(b));
  EXPECT_EQ(models[1].at("step"), std::to_string(swap_step));
  EXPECT_EQ(models[1].at("primitives"), "7");

  auto read = [](const fs::path& csv) { return dyad::testing::ReadCsv(csv / "robot_intention.csv"); };
  const auto with = read(first), without = read(none);
  ASSERT_EQ(with.size(), 40u);
  ASSERT_EQ(without.size(), 40u);
  for (size_t i = 0; i < with.size(); ++i) {
    if (i < swap_step)
      EXPECT_EQ(with[i].at("x"), without[i].at("x")) << "step " << i << ": A steers until the swap";
    else
      EXPECT_NE(with[i].at("x"), without[i].at("x")) << "step " << i << ": B steers from the swap on";
    EXPECT_EQ(with[i].at("iterations"), i == 0 ? "0" : "15") << "step " << i;
  }
  // The same in every run (but optimisation_s: the wall time the solves took).
  const auto again_with = read(again);
  ASSERT_EQ(again_with.size(), with.size());
  for (size_t i = 0; i < with.size(); ++i)
    for (const char* column : {"x", "y", "nelbo", "iterations"})
      EXPECT_EQ(with[i].at(column), again_with[i].at(column)) << "step " << i << ": two runs of one stepped graph swapped differently";
  for (const std::string f : {"mind_model.csv", "dyad_params.csv"}) {
    std::ostringstream x, y;
    x << std::ifstream(first / f).rdbuf();
    y << std::ifstream(again / f).rdbuf();
    EXPECT_EQ(x.str(), y.str()) << f << ": two runs of one stepped graph swapped differently";
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dyad::deliberator
