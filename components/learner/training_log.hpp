// components/learner/training_log.hpp: what a running `dyad train` has said so far, read from the
// log file its output goes to (the learner watches a training it started in another process).
//
// Update() reads what was appended since its last call and takes the complete lines:
//   "training ... from epoch 0 to N, ..."   -> epochs = N
//   "epoch E/N  ...  loss L  ..."           -> epoch = E, epochs = N, loss = L
// `last_line` is the newest non-empty line, `last_error` the newest that starts with "error: "
// (stderr is unbuffered and stdout is not: an error may come before lines printed earlier). A
// line that is none of those changes nothing else; a missing file reads as nothing yet.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

namespace dyad::learner {

class TrainingLog {
 public:
  void Update(const std::string& path);
  void TakeLine(const std::string& line);

  int64_t epoch = 0, epochs = 0;
  double loss = NAN;
  std::string last_line, last_error;

 private:
  int64_t offset_ = 0;  // bytes of the file already read
  std::string partial_;  // an incomplete last line, until its newline
};

}  // namespace dyad::learner
