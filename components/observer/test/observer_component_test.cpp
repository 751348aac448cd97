// The observer component through a fake context (no DDS): what it publishes while the human is
// engaged or not, the window restart, and the low-pass filtered congruence.
#include <gtest/gtest.h>

#include "dyad/testing/dds_domain.hpp"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/testing/fake_context.hpp"
#include "observer_component.hpp"

namespace dyad::observer {
namespace {

std::string ObserverPath() {
  static const std::string path = [] {
    ClassifierSpec s;
    s.hidden = {12, 8};
    ObserverFile f;
    f.classifier = Classifier::Create(s, 3).value();
    const std::string p =
        (std::filesystem::temp_directory_path() / ("dyad_observer_component_" + std::to_string(getpid()) + ".dobs")).string();
    EXPECT_TRUE(SaveObserver(f, p).ok());
    return p;
  }();
  return path;
}

msg::HumanInput Human(double x, double y, bool engaged) {
  msg::HumanInput h;
  h.x(x);
  h.y(y);
  h.engaged(engaged);
  return h;
}
msg::Intention Robot(double x, double y) {
  msg::Intention r;
  r.x(x);
  r.y(y);
  return r;
}

// Trajectories: robot at (k, -k), human at (2k, k) for step k.
struct Published {
  std::vector<msg::IntentionLabel> labels;
};

Published Drive(const std::vector<bool>& engaged, int64_t lowpass) {
  testing::FakeContext ctx(&Observer::Describe, {{"model", ObserverPath()}, {"lowpass_steps", lowpass}});
  auto& human = ctx.Feed<msg::HumanInput>("human");
  auto& robot = ctx.Feed<msg::Intention>("robot");
  auto& out = ctx.Capture<msg::IntentionLabel>("labels");
  Observer o;
  EXPECT_TRUE(o.Configure(ctx).ok());
  for (size_t k = 0; k < engaged.size(); ++k) {
    const double t = static_cast<double>(k);
    human.queue.push_back(Human(2 * t, t, engaged[k]));
    robot.queue.push_back(Robot(t, -t));
    ctx.PollInputs();
    EXPECT_TRUE(o.Step({.now_ns = 0, .index = k}).ok());
  }
  return {out.samples};
}

Eigen::VectorXd Expected(int last_step, bool human) {
  const Classifier c = LoadObserver(ObserverPath())->classifier;
  Eigen::MatrixXd w(2, 5);
  for (int i = 0; i < 5; ++i) {
    const double t = last_step - 4 + i;
    w.col(i) << (human ? 2 * t : t), (human ? t : -t);
  }
  Classifier::Workspace ws;
  Eigen::VectorXd p;
  c.Classify(w, &ws, &p);
  return p;
}

TEST(ObserverComponent, ClassifiesTheRobotOnceItsWindowIsFull) {
  const Published r = Drive(std::vector<bool>(7, false), 10);
  ASSERT_EQ(r.labels.size(), 7u);
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(r.labels[k].robot().empty()) << k;
  for (int k = 4; k < 7; ++k) {
    ASSERT_EQ(r.labels[k].robot().size(), 7u);
    const Eigen::VectorXd p = Expected(k, false);
    for (int i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(r.labels[k].robot()[i], p(i));
  }
  for (const auto& l : r.labels) {  // the human never engaged: no human classes, no congruence
    EXPECT_TRUE(l.human().empty());
    EXPECT_TRUE(std::isnan(l.congruence()));
  }
}

TEST(ObserverComponent, CongruenceIsTheMovingAverageWhileEngagedAndRestartsAfter) {
  // Engaged for steps 0..11, released at 12..13, engaged again from 14.
  std::vector<bool> engaged(20, true);
  engaged[12] = engaged[13] = false;
  const int64_t y = 3;
  const Published r = Drive(engaged, y);
  std::vector<double> c;  // instantaneous congruence from the first full window
  for (int k = 4; k < 12; ++k) {
    ASSERT_EQ(r.labels[k].human().size(), 7u) << k;
    c.push_back(InstantCongruence(Expected(k, true), Expected(k, false)));
    const size_t n = std::min<size_t>(c.size(), y);
    double mean = 0;
    for (size_t i = c.size() - n; i < c.size(); ++i) mean += c[i];
    EXPECT_NEAR(r.labels[k].congruence(), mean / n, 1e-12) << k;
  }
  for (int k : {0, 1, 2, 3, 12, 13, 14, 15, 16}) {  // window not yet full, or released
    EXPECT_TRUE(r.labels[k].human().empty()) << k;
    EXPECT_TRUE(std::isnan(r.labels[k].congruence())) << k;
  }
  // Re-engaged at 14: the window holds only positions from 14 on, full at 18; the filter restarts.
  ASSERT_EQ(r.labels[18].human().size(), 7u);
  const Eigen::VectorXd h18 = Expected(18, true);
  for (int i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(r.labels[18].human()[i], h18(i));
  EXPECT_NEAR(r.labels[18].congruence(), InstantCongruence(h18, Expected(18, false)), 1e-12);
}

TEST(ObserverComponent, ConfigureErrorsNameTheParameter) {
  testing::FakeContext ctx(&Observer::Describe, {{"model", ObserverPath()}, {"window", int64_t{6}}});
  Observer o;
  EXPECT_EQ(o.Configure(ctx).message(), "window = 6: " + ObserverPath() + " was trained with window 5");
  testing::FakeContext ctx2(&Observer::Describe, {{"model", std::string("/nonexistent.dobs")}});
  Observer o2;
  EXPECT_EQ(o2.Configure(ctx2).message(), "model: /nonexistent.dobs: cannot open");
}

// Loaded by type name in a real `dyad run`: a synthetic human feeds the observer (robot unbound).
TEST(ObserverPlugin, RunsInDyadWithASyntheticHuman) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("dyad_observer_run_" + std::to_string(getpid()));
  fs::create_directories(dir);
  ASSERT_TRUE(pvrnn::WriteNrlDataset(pvrnn::MakeAnalyticDataset(), (dir / "data").string()).ok());
  const fs::path g = dir / "g.yaml", err = dir / "err.txt";
  std::ofstream(g) << "graph: observe\nclock: stepped\ndomain_id: " << dyad::testing::DomainForThisProcess()
                   << "\ncomponents:\n"
                      "  human: {type: human_synthetic, rate_hz: 10, params: {dataset: "
                   << (dir / "data").string()
                   << ", events: [{start: 2, end: 20, primitive: 1}]}, outputs: {out: human/input}}\n"
                      "  observer: {type: observer, trigger: human, params: {model: "
                   << ObserverPath() << ", lowpass_steps: 10}, inputs: {human: human/input}, outputs: {labels: observer/labels}}\n";
  const std::string cmd = std::string(DYAD_EXE) + " run " + g.string() + " --steps 30 --quiet > /dev/null 2> " + err.string();
  const int rc = std::system(cmd.c_str());
  std::ifstream in(err);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(rc, 0) << text;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dyad::observer
