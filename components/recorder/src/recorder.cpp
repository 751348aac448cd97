#include "recorder.hpp"

#include <chrono>
#include <ctime>
#include <filesystem>

#include <dyad/msg/types.hpp>
#include <dyad/topic_select.hpp>
#include <dyad/join_list.hpp>
#include <dyad/private_file.hpp>

namespace dyad::recorder {
namespace {

std::string LocalTimeStamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

void ReplaceAll(std::string& s, const std::string& from, const std::string& to) {
  for (size_t pos = s.find(from); pos != std::string::npos; pos = s.find(from, pos + to.size())) s.replace(pos, from.size(), to);
}

// "demo/run" -> "demo_run": a graph name is a file-name fragment here.
std::string FileSafe(std::string s) {
  for (char& c : s)
    if (c == '/' || c == '\\' || c == ' ') c = '_';
  return s;
}

// The MCAP library's messages start with the file's path; the param prefix already names it.
std::string Detail(const std::string& message, const std::string& path) {
  if (message.rfind(path + ": ", 0) == 0) return message.substr(path.size() + 2);
  return message;
}

uint64_t NonNegative(int64_t v) { return v < 0 ? 0 : static_cast<uint64_t>(v); }

}  // namespace

void Recorder::Describe(ComponentSpec& spec) {
  spec.Summary("Records graph topics (names or regexes, default all) into an MCAP file: omgidl schemas, CDR, zstd chunks.");
  spec.Param("file", "{graph}-{time}.mcap").Path().Doc("output path; {graph} = graph name, {time} = local start time YYYYMMDD-HHMMSS");
  spec.Param("overwrite", false).Doc(
      "replace an existing file (false: an existing file is an error, nothing is recorded over it); either way the "
      "file is created 0600 and never through a symlink");
  spec.Param("metadata", std::vector<std::string>{}).Doc(
      "KEY=VALUE entries kept in the file as its \"dyad.run\" metadata (who ran it and why: `dyad study run` names the "
      "study, participant, condition and trial)");
  spec.Param("topics", std::vector<std::string>{}).Doc("topic names or regexes (whole-name match); empty: every graph topic");
  spec.Param("chunk_size", int64_t{256 * 1024}).Range(1024, 1024.0 * 1024 * 1024).Unit("bytes").Doc("uncompressed bytes per chunk");
  spec.Param("compression", "zstd").OneOf({"zstd", "none"}).Doc("chunk compression");
  spec.Param("compression_level", int64_t{1}).Range(1, 19).Doc("zstd level (1 fastest)");
  spec.Param("queue_mb", int64_t{64}).Range(1, 4096).Unit("MiB").Doc("hand-over queue bound; when full the publisher waits, nothing is dropped");
  spec.Output<msg::RecordingStatus>("status").Optional().Doc(
      "what it records: file, samples and bytes so far, elapsed time, a write failure (the experimenter's page shows it), "
      "each step");
  spec.Param("flush_period_s", 1.0).Min(0).Unit("s").Doc("wall clock: close the current chunk at least this often (0: only when full)");
}

std::string Recorder::ExpandFileName(const std::string& pattern, const std::string& graph, const std::string& time) {
  std::string s = pattern;
  ReplaceAll(s, "{graph}", FileSafe(graph));
  ReplaceAll(s, "{time}", time);
  return s;
}

Status Recorder::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  path_ = ExpandFileName(p.String("file"), ctx.graph_name(), LocalTimeStamp());
  if (path_.empty()) return Status::InvalidArgument("params.file: must not be empty");
  // Checked before anything runs: a recording is never silently replaced by the next run. (Said
  // early; Activate's exclusive creation is what guarantees it.)
  options_.replace_existing = p.Bool("overwrite");
  if (!p.Bool("overwrite") && std::filesystem::exists(std::filesystem::symlink_status(path_)))
    return Status::InvalidArgument("params.file = '" + path_ + "': exists; set params.overwrite: true to replace it, or put " +
                                   "{time} in the name (there now: " + WhatIsAt(path_) +
                                   "; a link is replaced as an entry, its target never written)");
  if (std::filesystem::is_directory(std::filesystem::symlink_status(path_)))
    return Status::InvalidArgument("params.file = '" + path_ + "': is a folder; name a file in it");
  options_.chunk_size = static_cast<uint64_t>(p.Int("chunk_size"));
  options_.compression = p.String("compression") == "none" ? mcap::Compression::kNone : mcap::Compression::kZstd;
  options_.zstd_level = static_cast<int>(p.Int("compression_level"));
  options_.library = "dyad recorder";
  if (Status s = options_.Validate(); !s.ok()) return Status::InvalidArgument("params: " + s.message());
  flush_period_s_ = ctx.stepped() ? 0.0 : p.Double("flush_period_s");
  run_metadata_.clear();
  for (const std::string& entry : p.StringList("metadata")) {
    const size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0)
      return Status::InvalidArgument("params.metadata: '" + entry + "' is not KEY=VALUE");
    const std::string key = entry.substr(0, eq);
    if (run_metadata_.count(key)) return Status::InvalidArgument("params.metadata: key '" + key + "' is given twice");
    run_metadata_[key] = entry.substr(eq + 1);
  }

  std::vector<std::string> names;
  for (const auto& t : ctx.graph_topics()) names.push_back(t.name);
  auto chosen = SelectTopics(p.StringList("topics"), names, "params.topics");
  if (!chosen.ok()) return chosen.status();
  if (chosen->empty()) return Status::InvalidArgument("params.topics: the graph has no topic to record");

  status_ = &ctx.output<msg::RecordingStatus>("status");
  status_msg_.component_name(ctx.name());
  status_msg_.file(std::filesystem::absolute(path_).lexically_normal().string());
  first_step_ns_.reset();
  queue_ = std::make_unique<RecordQueue>(static_cast<size_t>(p.Int("queue_mb")) << 20);
  for (const auto& name : *chosen) {
    const TopicInfo* info = nullptr;
    for (const auto& t : ctx.graph_topics())
      if (t.name == name) info = &t;
    auto ch = std::make_unique<Channel>();
    ch->topic = info;
    Channel* raw = ch.get();
    const auto id = static_cast<uint16_t>(channels_.size() + 1);
    channels_.push_back(std::move(ch));
    RecordQueue* queue = queue_.get();
    Status s = ctx.SubscribeSerialized(name, [queue, raw, id](const SerializedSample& sample) {
      RecordEntry e;
      e.channel = id;
      e.sequence = static_cast<uint32_t>(sample.sequence);
      e.log_time = NonNegative(sample.receive_ns);
      e.publish_time = NonNegative(sample.source_stamp_ns);
      if (queue->Push(e, sample.cdr)) raw->received.fetch_add(1, std::memory_order_relaxed);
    });
    if (!s.ok()) return Status::Internal("params.topics: cannot subscribe to '" + name + "': " + s.message());
  }
  return Status::OK();
}

Status Recorder::Activate() {
  Status s = OpenFile();
  // Without a writer thread a full queue would block publishers forever: refuse pushes instead.
  if (!s.ok()) queue_->Close();
  return s;
}

Status Recorder::OpenFile() {
  // Missing folders are created 0700, the file 0600, exclusively (unless overwrite): a file or a
  // symlink that appeared at the path since Configure is an error, its target untouched.
  if (Status s = CreatePrivateDirectories(std::filesystem::path(path_).parent_path().string()); !s.ok())
    return Status::IOError("params.file = '" + path_ + "': " + s.message());
  auto w = mcap::Writer::Open(path_, options_);
  if (!w.ok()) return Status::IOError("params.file = '" + path_ + "': " + Detail(w.status().message(), path_));
  writer_ = std::make_unique<mcap::Writer>(std::move(w.value()));
  for (size_t i = 0; i < channels_.size(); ++i) {
    const TopicInfo& t = *channels_[i]->topic;
    auto schema = writer_->AddSchema(t.type->name, "omgidl", t.type->idl);
    if (!schema.ok()) return schema.status();
    auto id = writer_->AddChannel(t.name, "cdr", *schema,
                                  {{"dds_type", t.type->dds_name()},
                                   {"reliability", t.reliable ? "reliable" : "best_effort"},
                                   {"depth", std::to_string(t.depth)}});
    if (!id.ok()) return id.status();
    if (*id != i + 1) return Status::Internal("MCAP channel id " + std::to_string(*id) + " for '" + t.name + "', expected " + std::to_string(i + 1));
  }
  if (Status s = writer_->AddMetadata("dyad.graph", {{"name", ctx_->graph_name()},
                                                     {"clock", ctx_->stepped() ? "stepped" : "wall"},
                                                     {"yaml", ctx_->graph_yaml()},
                                                     {"folder", ctx_->graph_folder()}});
      !s.ok())
    return s;
  if (!run_metadata_.empty())
    if (Status s = writer_->AddMetadata("dyad.run", run_metadata_); !s.ok()) return s;
  thread_ = std::thread([this] { WriterLoop(); });
  const std::string list = JoinList(channels_, [](const auto& c) -> const std::string& { return c->topic->name; });
  ctx_->log().Info("recording " + std::to_string(channels_.size()) + " topic(s) into " + path_ + ": " + list);
  return Status::OK();
}

void Recorder::WriterLoop() {
  RecordBatch batch;
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(flush_period_s_));
  auto next_flush = Clock::now() + period;
  // A quarter arena wakes it at once; else every 100 ms (a session's few kB/s need no more: 20 ms
  // woke each of a study server's dozens of recorders 50 times a second).
  constexpr int kHandOverMs = 100;
  while (queue_->TakeBatch(&batch, kHandOverMs)) {
    if (!failed_.load(std::memory_order_relaxed)) {
      batch.ForEach([&](const RecordEntry& e, std::span<const uint8_t> data) {
        if (failed_.load(std::memory_order_relaxed)) return;
        if (Status s = writer_->Write(e.channel, e.sequence, e.log_time, e.publish_time, data); !s.ok()) SetFailure(s);
      });
    }  // after a failure the queue is still drained, so publishers never block on a dead writer
    if (flush_period_s_ > 0 && Clock::now() >= next_flush && !failed_.load(std::memory_order_relaxed)) {
      if (Status s = writer_->Flush(); !s.ok()) SetFailure(s);
      next_flush = Clock::now() + period;
    }
    bytes_written_.store(writer_->bytes_written(), std::memory_order_relaxed);  // the writer is this thread's alone
  }
}

void Recorder::SetFailure(const Status& s) {
  std::lock_guard<std::mutex> lock(failure_mutex_);
  if (failure_.ok()) failure_ = Status::IOError("params.file = '" + path_ + "': " + Detail(s.message(), path_));
  failed_.store(true, std::memory_order_release);
}

Status Recorder::failure() const {
  std::lock_guard<std::mutex> lock(failure_mutex_);
  return failure_;
}

Status Recorder::Step(const StepInfo& info) {
  const bool failed = failed_.load(std::memory_order_acquire);
  if (status_->bound()) {
    if (!first_step_ns_) first_step_ns_ = info.now_ns;
    uint64_t samples = 0;
    for (const auto& c : channels_) samples += c->received.load(std::memory_order_relaxed);
    status_msg_.samples(samples);
    status_msg_.bytes(bytes_written_.load(std::memory_order_relaxed));
    status_msg_.elapsed_s(static_cast<double>(info.now_ns - *first_step_ns_) * 1e-9);
    status_msg_.error(failed ? failure().message() : std::string());
    // Said before the failure ends the run: the page shows why.
    if (Status s = status_->Publish(status_msg_); !s.ok() && !failed) return s;
  }
  if (failed) return failure();
  return Status::OK();
}

Status Recorder::Deactivate() {
  if (!thread_.joinable()) return Status::OK();
  queue_->Close();  // the runtime closed our subscriptions: nothing more will be pushed
  thread_.join();
  if (Status s = writer_->Close(); !s.ok()) SetFailure(s);
  uint64_t total = 0;
  std::string counts;
  for (const auto& c : channels_) {
    const uint64_t n = c->received.load();
    total += n;
    counts += (counts.empty() ? "" : ", ") + c->topic->name + " " + std::to_string(n);
  }
  const double mb = static_cast<double>(writer_->bytes_written()) / 1e6;
  char size[32];
  std::snprintf(size, sizeof size, "%.2f", mb);
  ctx_->log().Info("recorded " + std::to_string(total) + " samples into " + path_ + " (" + size + " MB; " + counts +
                   "; queue high water " + std::to_string(queue_->high_water_bytes() >> 10) + " KiB, publisher waits " +
                   std::to_string(queue_->producer_waits()) + ")");
  return failure();
}

void Recorder::Shutdown() {
  if (thread_.joinable()) {
    queue_->Close();
    thread_.join();
  }
  // Deactivate closed the file and reported how; here only when it never ran (a failed start).
  if (writer_)
    if (Status s = writer_->Close(); !s.ok()) ctx_->log().Error(path_ + ": " + s.message());
}

}  // namespace dyad::recorder
