// tools/study/study_task.hpp: what the subject's page shows during a study's trials, from the
// study file (docs/study.md, "The task on the subject's page"): a primitive to draw (or a
// sequence, one per repetition of the condition), a message, a countdown at the trial's start,
// practice. The study's web component shows it (its task_* and practice params, which also
// publish it on its `task` output: recorded as subject/task when the recorder lists it).
//
//   task: {message: "Draw the shape", target: 2, countdown: 3}   # every trial
//   conditions:
//     assist: {mixer.gain: 0.3, task: {sequence: [0, 3], practice: true}}   # this condition's own
//
// A condition's `task` replaces the file's fields it names. `sequence` gives repetition r of the
// condition the primitive sequence[(r - 1) % n] (it replaces `target`). Keys: message (text),
// target (the data set's primitive, -1 none), sequence (a list of them), countdown (s, >= 0),
// practice (true|false). Each is checked against the graph (the web component's own checks:
// a target the data set has not is refused at its line).
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dyad/strict_yaml.hpp"

namespace dyad::study {

struct StudyTask {
  bool any = false;  // some field is set (else nothing is sent to the page)
  std::string message;
  int target = -1;
  std::vector<int> sequence;
  double countdown_s = 0;
  bool practice = false;
};

// Reads `node` (a map) at `where` over `base`; false after saying what is wrong.
bool ReadTask(StrictYaml& y, const YAML::Node& node, const std::string& where, StudyTask* task);

// The overrides that show `task` on `web`'s page in repetition `repetition` (1-based) of its
// condition (none without a task or a web). The runner adds the time left (WEB.task_time_s).
std::vector<std::string> TaskSets(const std::string& web, const StudyTask& task, int repetition);

}  // namespace dyad::study
