/// The `recorder` component: records graph topics into an MCAP file.
///
/// @component recorder
/// rate_hz: any (1 is plenty): each step only checks that the writer thread is healthy; samples
///          are taken as they are published, not per step.
/// inputs: none (topics are subscribed generically, Context::SubscribeSerialized)
/// params:
///   file (string, "{graph}-{time}.mcap"): output path; {graph} = graph name, {time} = local
///        start time YYYYMMDD-HHMMSS. Missing parent folders are created.
///   metadata (string list, []): KEY=VALUE entries written as the file's "dyad.run" metadata
///        record (who ran it and why: `dyad study run` names study, participant, condition,
///        trial); a malformed entry or a key given twice is an error.
///   topics (string list, []): topic names or regular expressions (whole-name match); empty:
///        every topic of the graph, dyad/stats included.
///   chunk_size (int, 262144 bytes, 1 KiB .. 1 GiB): uncompressed bytes per MCAP chunk.
///   compression (string, "zstd"): zstd | none.
///   compression_level (int, 1, 1..19): zstd level.
///   queue_mb (int, 64, 1..4096): bound of the hand-over queue; when it is full the publisher
///        waits (back-pressure), nothing is dropped.
///   flush_period_s (double, 1.0, >= 0): wall clock only: close the current chunk at least this
///        often, bounding what a crash loses in time; 0: only when a chunk is full.
/// outputs:
///   status (RecordingStatus, optional): each step, the file, the samples taken and bytes written
///        so far, the seconds since its first step, and a write failure's message (published in
///        the step that then fails the run).
/// @endcomponent
///
/// The file: one `omgidl` schema per message type (the IDL text, includes inlined, named by the
/// IDL type name), one `cdr` channel per topic (metadata: dds_type = "name#hash", reliability,
/// depth), messages with log_time = receive time and publish_time = the sample's DDS source
/// timestamp (= its header stamp for dyad writers; both Unix ns under the wall clock, simulated
/// ns under the stepped clock), sequence = the writer's sequence number (low 32 bits); zstd
/// chunks; a summary section; metadata "dyad.graph" {name, clock, yaml} with the graph file as
/// run (--set overrides applied); metadata "dyad.run" with the `metadata` param's entries, when any.
///
/// Threads: samples are copied into a RecordQueue on the delivering thread (a lock and a memcpy);
/// one writer thread owned by the recorder writes and compresses chunks. Deactivate() (normal end,
/// SIGINT/SIGTERM, a failure elsewhere) writes every queued sample and finishes the file; a killed
/// process leaves a file readable up to its last complete chunk. Under the stepped clock chunks
/// are cut by size only, so the same graph and seed give a byte-identical file (dyad/stats aside:
/// it carries wall-clock timings).
///
/// Lifecycle: Configure chooses topics and subscribes (errors name the param); Activate opens the
/// file (error names `file`) and starts the writer thread; Step reports a failed write;
/// Deactivate flushes and closes; Shutdown stops the thread if Deactivate was not reached.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/mcap/writer.hpp>
#include <dyad/msg/types.hpp>

#include "record_queue.hpp"

namespace dyad::recorder {

class Recorder final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Activate() override;
  Status Step(const StepInfo& info) override;
  Status Deactivate() override;
  void Shutdown() override;

  // "{graph}" and "{time}" replaced; exposed for tests.
  static std::string ExpandFileName(const std::string& pattern, const std::string& graph, const std::string& time);

 private:
  struct Channel {
    const TopicInfo* topic = nullptr;  // owned by the runtime
    std::atomic<uint64_t> received{0};
  };
  Status OpenFile();  // Activate(): file, schemas, channels, metadata, writer thread
  void WriterLoop();
  void SetFailure(const Status& s);
  Status failure() const;

  Context* ctx_ = nullptr;
  std::string path_;
  mcap::WriterOptions options_;
  double flush_period_s_ = 1.0;
  std::map<std::string, std::string> run_metadata_;  // params.metadata
  std::vector<std::unique_ptr<Channel>> channels_;  // channel id = index + 1
  std::unique_ptr<RecordQueue> queue_;
  std::unique_ptr<mcap::Writer> writer_;
  std::thread thread_;
  std::atomic<bool> failed_{false};
  mutable std::mutex failure_mutex_;
  Status failure_;
  Output<msg::RecordingStatus>* status_ = nullptr;  // optional: unbound, nothing is published
  msg::RecordingStatus status_msg_;
  std::optional<int64_t> first_step_ns_;  // the run's clock at the first step: elapsed_s counts from it
  std::atomic<uint64_t> bytes_written_{0};  // the writer thread's count, for the step thread
};

}  // namespace dyad::recorder
