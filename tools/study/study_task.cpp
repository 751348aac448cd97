#include "study_task.hpp"

#include "yaml_file.hpp"

namespace dyad::study {

bool ReadTask(StrictYaml& y, const YAML::Node& node, const std::string& where, StudyTask* task) {
  if (!y.Map(node, where, {"message", "target", "sequence", "countdown", "practice"})) return false;
  bool ok = true;
  StudyTask t = *task;
  if (node["message"]) ok = y.Get(node["message"], where + ".message", &t.message, "a text") && ok;
  if (node["target"])
    ok = y.Get(node["target"], where + ".target", &t.target, "a primitive of the data set (0, 1, ...; -1: none)") && ok;
  if (node["target"] && t.target < -1) ok = (y.Error(node["target"], where + ".target", "must be -1 or more"), false);
  if (node["sequence"]) {
    ok = y.Get(node["sequence"], where + ".sequence", &t.sequence, "a list of primitives of the data set") && ok;
    if (node["sequence"].IsSequence() && node["sequence"].size() == 0)
      ok = (y.Error(node["sequence"], where + ".sequence", "name at least one primitive"), false);
    for (const int k : t.sequence)
      if (k < 0)
        ok = (y.Error(node["sequence"], where + ".sequence", "a primitive is 0 or more, got " + std::to_string(k)), false);
  }
  if (node["countdown"]) ok = y.Get(node["countdown"], where + ".countdown", &t.countdown_s, "seconds") && ok;
  if (node["countdown"] && t.countdown_s < 0) ok = (y.Error(node["countdown"], where + ".countdown", "must be 0 or more"), false);
  if (node["practice"]) ok = y.Get(node["practice"], where + ".practice", &t.practice, "true or false") && ok;
  if (node["target"] && !node["sequence"]) t.sequence.clear();  // the condition's target replaces the file's sequence
  t.any = true;
  if (ok) *task = t;
  return ok;
}

std::vector<std::string> TaskSets(const std::string& web, const StudyTask& task, int repetition) {
  if (!task.any || web.empty()) return {};
  const int target =
      task.sequence.empty() ? task.target : task.sequence[static_cast<size_t>(repetition - 1) % task.sequence.size()];
  std::vector<std::string> sets = {web + ".task_target=" + std::to_string(target),
                                   web + ".task_message=" + tools::YamlQuoted(task.message),
                                   web + ".practice=" + (task.practice ? "true" : "false")};
  if (task.countdown_s > 0) sets.push_back(web + ".task_countdown_s=" + tools::SetText(YAML::Node(task.countdown_s)));
  return sets;
}

}  // namespace dyad::study
