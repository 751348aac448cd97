/// The `replay` component: republishes the topics of an MCAP recording.
///
/// @component replay
/// rate_hz: required. Wall clock: each step publishes every message that is due (timing
///          resolution = the period; 100..1000 Hz is typical). Stepped clock: each step publishes
///          the next batch (the messages sharing one log time, i.e. one recorded instant).
/// inputs, outputs: none (topics are advertised generically, Context::AdvertiseSerialized)
/// params:
///   file (string, required): the recording (a file cut short is replayed up to its last chunk).
///   topics (string list, []): recorded topics, names or regexes; empty: all but dyad/stats.
///   remap (yaml, {}): recorded topic -> topic to publish on, e.g. {human/input: replay/human}.
///   speed (double, 1.0, > 0): wall clock: time scale (2 = twice as fast).
///   start_s (double, 0, >= 0): skip the first seconds of the recording (from its first chosen message).
///   loop (bool, false): start over after the last message until the run ends (never asks it to stop).
/// @endcomponent
///
/// Messages are published in log-time order as recorded, bytes unchanged (headers keep their
/// source, sequence and stamp), with the DDS source timestamp set to the recorded publish_time.
/// Each topic's type must be known to this process with the recorded definition (the channel's
/// dds_type "name#hash", else the IDL text, must match); otherwise Configure fails naming the topic.
/// When the last message has been published the component asks the run to stop (unless `loop`).
/// The chosen messages are loaded into memory in Configure (their uncompressed size).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/mcap/reader.hpp>

namespace dyad::recorder {

class Replay final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Activate() override;
  Status Step(const StepInfo& info) override;

 private:
  struct Message {
    uint32_t writer = 0;  // index into writers_
    uint64_t log_time = 0;
    uint64_t publish_time = 0;
    uint32_t offset = 0, size = 0;  // in bytes_
  };
  Status PublishUpTo(size_t end);
  Status SkipStart(double start_s);

  Context* ctx_ = nullptr;
  std::string path_;
  double speed_ = 1.0;
  bool loop_ = false;
  size_t begin_ = 0;   // the first message played (start_s)
  std::vector<std::string> topics_;  // recorded topic per writer
  std::vector<SerializedWriter*> writers_;  // owned by the runtime
  std::vector<Message> messages_;
  std::vector<uint8_t> bytes_;
  size_t next_ = 0;
  int64_t start_ns_ = -1;  // clock time of the first step
  bool done_ = false;
};

}  // namespace dyad::recorder
