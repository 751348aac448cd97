// dyad/observer/observer_file.hpp: the trained observer (intention classifier) file, `.dobs`.
//
// Format (all integers little-endian), the same frame as the PV-RNN model file:
//   bytes 0..7    magic "DYADOBSV"
//   u32           format version (kObserverFileVersion)
//   u32           flags (0)
//   u64           J = length of the JSON header
//   J bytes       JSON: {"format", "spec": {window, hidden, classes, input, workspace [[min,max]..]},
//                 "parameters": count, "provenance": {...}}
//   payload       the classifier's flat parameter vector, IEEE-754 doubles, little-endian
//   u32           CRC-32 (zlib) of every byte before it
// Contract
// - `SaveObserver` writes `path.tmp` then renames it, so a crash never leaves a half file.
// - `LoadObserver` never crashes on bad input: a missing, truncated, corrupted (checksum),
//   wrong-magic, wrong-version or inconsistent file gives a Status whose message starts with
//   the path and says what is wrong.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "dyad/observer/classifier.hpp"

namespace dyad::observer {

inline constexpr uint32_t kObserverFileVersion = 1;

struct ObserverProvenance {
  std::string source;                  // e.g. "dyad train-observer build/models/demo.dpvrnn"
  std::string model;                   // PV-RNN model the training data came from
  std::vector<uint64_t> train_seeds;   // prior-noise seeds of the training data
  std::vector<uint64_t> validation_seeds;
  int steps = 0, drop = 0;             // generated steps per trajectory, dropped steps
  int epochs = 0;
  uint64_t seed = 0;                   // init/shuffle seed
  double validation_min_diagonal = std::numeric_limits<double>::quiet_NaN();
  double validation_accuracy = std::numeric_limits<double>::quiet_NaN();
};

struct ObserverFile {
  Classifier classifier;
  ObserverProvenance provenance;
};

Status SaveObserver(const ObserverFile& observer, const std::string& path);
StatusOr<ObserverFile> LoadObserver(const std::string& path);

}  // namespace dyad::observer
