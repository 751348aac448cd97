// Round-trip latency of a sample through two dyad components (bench_ping -> bench_pong -> back)
// versus two bare Fast DDS endpoints doing the same (same type, QoS, transport), alternating in
// one run. Prints median and p99 of each and their ratio.
//
//   build/bin/bench_pingpong [--rounds N] [--repeats R] [--payload BYTES]
//                            [--processes [--pong-prefix "ip netns exec NS"]] [--security] [--only bare|dyad]
//                            [--evict KIB]
//
// --only runs one contender (no ratio), for a profile of its path alone; e.g. instructions per
// round trip under callgrind, which a loaded machine does not disturb (docs/runtime.md,
// "Benchmark: a hop through dyad vs bare Fast DDS"):
//   valgrind --tool=callgrind build-cg/bin/bench_pingpong --only dyad --rounds 2000 --repeats 1
// and again with --rounds 4000: the difference over 2000 is one round trip's (set-up cancels).
// (callgrind needs a build without -march=native: cmake -DDYAD_NATIVE=OFF.)
//
// --security adds a third contender, alternating with the others: the same dyad graph with a
// `security:` keystore (`dyad security init`: authentication, access control, everything
// encrypted; docs/security.md), and the ratio secured/dyad. Use it with --processes: inside one
// process samples never reach the wire, so there is nothing to encrypt.
//
// --evict KIB writes a buffer of KIB KiB before each round trip, outside the timed part, on both
// sides: each round trip then starts with the core's caches (L1, L2) and first-level TLBs cold,
// as after the thread was preempted or the vCPU descheduled, which is what the slow round trips
// of a plain run are (docs/runtime.md); 4096 measures that path alone.
//
// --processes puts pong in a second OS process (bare: this binary with --bare-pong; dyad: a
// `dyad run --process pong` child of a two-process graph), started with the words of
// --pong-prefix in front: run the whole benchmark in one network namespace with the pong side in
// another (bench/pingpong/bench_netns.sh) and the round trip crosses a veth pair.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <mutex>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include <dyad/msg/types.hpp>
#include <dyad/run.hpp>

namespace fdds = eprosima::fastdds::dds;

namespace {

int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The bare Fast DDS version, doing what the two dyad components do: pong's listener takes the
// sample and replies at once; ping, like a component that is busy in its own step while the
// reply is delivered (inside its own write()), takes the reply once its write() has returned and
// then sends the next one. The round trip is measured the same way on both sides: from just
// before the ping's write() to the moment the sender has taken the reply. (Measuring bare ping
// inside the nested listener instead would stop the clock before either write() has finished.)
class BarePingPong {
 public:
  enum class Role { kBoth, kPing, kPong };
  BarePingPong(int domain, size_t payload, Role role = Role::kBoth, size_t evict_kb = 0) : junk_(evict_kb * 1024), role_(role) {
    auto* f = fdds::DomainParticipantFactory::get_instance();
    // The transports dyad's participants use (runtime/dds/network_qos.cpp, the default network
    // section): shared memory first, then UDPv4, declared explicitly.
    fdds::DomainParticipantQos pq = f->get_default_participant_qos();
    pq.transport().use_builtin_transports = false;
    pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
    pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
    participant_ = f->create_participant(domain, pq);
    const auto& info = dyad::TypeInfoOf<dyad::msg::PingPong>();
    fdds::TypeSupport ts(info.make_type_support());
    ts.register_type(participant_, info.dds_name());
    auto* ping_topic = participant_->create_topic("bare/ping", info.dds_name(), fdds::TOPIC_QOS_DEFAULT);
    auto* pong_topic = participant_->create_topic("bare/pong", info.dds_name(), fdds::TOPIC_QOS_DEFAULT);
    auto* pub = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    auto* sub = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    fdds::DataWriterQos wq = fdds::DATAWRITER_QOS_DEFAULT;
    wq.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
    wq.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
    wq.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    wq.history().depth = 1;
    fdds::DataReaderQos rq = fdds::DATAREADER_QOS_DEFAULT;
    rq.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
    rq.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
    rq.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    rq.history().depth = 1;
    pong_listener_.owner = this;
    ping_listener_.owner = this;
    if (role != Role::kPong) {
      ping_writer_ = pub->create_datawriter(ping_topic, wq);
      back_reader_ = sub->create_datareader(pong_topic, rq, &ping_listener_, fdds::StatusMask::data_available());
    }
    if (role != Role::kPing) {
      pong_writer_ = pub->create_datawriter(pong_topic, wq);
      sub->create_datareader(ping_topic, rq, &pong_listener_, fdds::StatusMask::data_available());
    }
    sample_.payload().resize(payload);
  }
  // The ping side of a split run: until the pong process's endpoints have matched.
  bool WaitForPong(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    fdds::PublicationMatchedStatus pub;
    fdds::SubscriptionMatchedStatus sub;
    while (std::chrono::steady_clock::now() < end) {
      ping_writer_->get_publication_matched_status(pub);
      back_reader_->get_subscription_matched_status(sub);
      if (pub.current_count > 0 && sub.current_count > 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  ~BarePingPong() {
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  std::vector<int64_t> Run(int rounds) {
    rtt_.clear();
    rtt_.reserve(rounds);
    if (role_ == Role::kPing) return RunFromListener(rounds);
    fdds::SampleInfo info;
    while (static_cast<int>(rtt_.size()) < rounds) {
      pending_.store(false);
      for (size_t i = 0; i < junk_.size(); i += 64) junk_[i] = static_cast<char>(junk_[i] + 1);
      sample_.id(sample_.id() + 1);
      sample_.t0_ns(SteadyNs());
      ping_writer_->write(&sample_);
      if (!pending_.load()) {  // delivered on another thread: wait for it
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait_for(lock, std::chrono::seconds(1), [&] { return pending_.load(); });
      }
      while (back_reader_->take_next_sample(&reply_, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data && reply_.id() == sample_.id()) rtt_.push_back(SteadyNs() - reply_.t0_ns());
      }
    }
    return rtt_;
  }

 private:
  // Split run: the reply arrives on a Fast DDS receive thread, and ping answers it there (takes
  // it, notes the round trip, writes the next ping), as a dyad component triggered by it does.
  // Waking another thread for each reply instead would add a thread switch to bare Fast DDS only.
  std::vector<int64_t> RunFromListener(int rounds) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      rounds_ = rounds;
      done_ = false;
      sample_.id(sample_.id() + 1);
      sample_.t0_ns(SteadyNs());
    }
    ping_writer_->write(&sample_);
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return done_; });
    return rtt_;
  }
  void OnReply() {  // the ping listener, split run
    fdds::SampleInfo info;
    std::unique_lock<std::mutex> lock(mutex_);
    bool again = false;
    while (back_reader_->take_next_sample(&reply_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || reply_.id() != sample_.id()) continue;
      rtt_.push_back(SteadyNs() - reply_.t0_ns());
      again = static_cast<int>(rtt_.size()) < rounds_;
      done_ = !again;
    }
    if (done_) cv_.notify_one();
    if (!again) return;
    for (size_t i = 0; i < junk_.size(); i += 64) junk_[i] = static_cast<char>(junk_[i] + 1);
    sample_.id(sample_.id() + 1);
    sample_.t0_ns(SteadyNs());
    lock.unlock();
    ping_writer_->write(&sample_);
  }

  struct PongListener : fdds::DataReaderListener {
    BarePingPong* owner;
    dyad::msg::PingPong s;
    void on_data_available(fdds::DataReader* r) override {
      fdds::SampleInfo info;
      while (r->take_next_sample(&s, &info) == ReturnCode_t::RETCODE_OK)
        if (info.valid_data) owner->pong_writer_->write(&s);
    }
  };
  struct PingListener : fdds::DataReaderListener {
    BarePingPong* owner;
    void on_data_available(fdds::DataReader*) override {
      if (owner->role_ == Role::kPing) {
        owner->OnReply();
        return;
      }
      std::lock_guard<std::mutex> lock(owner->mutex_);
      owner->pending_.store(true);
      owner->cv_.notify_one();
    }
  };
  fdds::DomainParticipant* participant_ = nullptr;
  fdds::DataWriter* ping_writer_ = nullptr;
  fdds::DataWriter* pong_writer_ = nullptr;
  fdds::DataReader* back_reader_ = nullptr;
  PongListener pong_listener_;
  PingListener ping_listener_;
  dyad::msg::PingPong sample_, reply_;
  std::vector<int64_t> rtt_;
  std::vector<char> junk_;  // --evict
  std::atomic<bool> pending_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  Role role_ = Role::kBoth;
  int rounds_ = 0;     // split run
  bool done_ = false;  // split run: rounds_ replies taken
};

// Starts `args` (with `prefix` in front) as a child; its pid.
pid_t Spawn(const std::vector<std::string>& prefix, std::vector<std::string> args) {
  args.insert(args.begin(), prefix.begin(), prefix.end());
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    std::perror("bench_pingpong: exec");
    _exit(127);
  }
  return pid;
}

void Stop(pid_t pid) {
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
}

// `secured`: with the keystore DIR/keys, made on first use.
std::vector<int64_t> RunDyad(int domain, int rounds, size_t payload, size_t evict_kb, const std::string& dir, bool processes,
                             const std::vector<std::string>& pong_prefix, bool secured = false) {
  const std::string graph = dir + (secured ? "/pingpong_secured.yaml" : "/pingpong.yaml");
  const std::string out = dir + "/rtt.txt";
  std::ofstream(graph) << "graph: pingpong\nclock: wall\ndomain_id: " << domain << (secured ? "\nsecurity: {keystore: keys}" : "")
                       << (processes ? "\nprocesses: {ping: {}, pong: {}}" : "")
                       << "\ncomponents:\n"
                          "  pong: {type: bench_pong, trigger: in, inputs: {in: ping}, outputs: {out: pong}"
                       << (processes ? ", process: pong" : "")
                       << "}\n"
                          "  ping: {type: bench_ping, trigger: back, params: {rounds: "
                       << rounds << ", payload: " << payload << ", evict_kb: " << evict_kb << ", file: " << out
                       << "}, inputs: {back: pong}, outputs: {out: ping}" << (processes ? ", process: ping" : "")
                       << "}\n"
                          "topics:\n  ping: {reliability: reliable, depth: 1}\n  pong: {reliability: reliable, depth: 1}\n";
  if (secured && !std::filesystem::exists(dir + "/keys")) {
    const std::string init = std::string(DYAD_EXE) + " security init '" + dir + "/keys' --graph '" + graph +
                             "' --plugins '" + DYAD_BENCH_PLUGIN + "' > '" + dir + "/init.log'";
    if (std::system(init.c_str()) != 0) {
      std::cerr << "bench_pingpong: dyad security init failed\n";
      std::exit(1);
    }
  }
  dyad::RunOptions o;
  o.graph_path = graph;
  o.quiet = true;
  o.plugin_paths = {DYAD_BENCH_PLUGIN};
  pid_t pong = 0;
  if (processes) {
    o.process = "ping";
    pong = Spawn(pong_prefix, {DYAD_EXE, "run", graph, "--process", "pong", "--quiet", "--plugins", DYAD_BENCH_PLUGIN});
  }
  std::ostringstream sink;
  const int code = dyad::RunGraph(o, sink, std::cerr);
  if (pong != 0) Stop(pong);
  if (code != 0) {
    std::cerr << "dyad run failed\n";
    std::exit(1);
  }
  std::vector<int64_t> v;
  std::ifstream in(out);
  for (int64_t x; in >> x;) v.push_back(x);
  return v;
}

double Percentile(std::vector<int64_t> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return static_cast<double>(v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))]) * 1e-3;
}

// Percent of the round trips that took more than twice the median: the slow mode (docs/runtime.md,
// "why p99 lags the median"). Above 1 % it holds the p99.
double SlowPercent(const std::vector<int64_t>& v) {
  if (v.empty()) return 0;
  const double limit = 2 * 1e3 * Percentile(v, 0.5);  // Percentile is in us, v in ns
  const auto slow = std::count_if(v.begin(), v.end(), [&](int64_t x) { return static_cast<double>(x) > limit; });
  return 100.0 * static_cast<double>(slow) / static_cast<double>(v.size());
}

double Mean(const std::vector<int64_t>& v) {
  double sum = 0;
  for (int64_t x : v) sum += static_cast<double>(x);
  return v.empty() ? 0 : sum / static_cast<double>(v.size()) * 1e-3;
}

// --bare-pong DOMAIN PAYLOAD: the pong side of the bare split run, until SIGTERM.
int BarePongMain(int domain, size_t payload) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);  // before Fast DDS's threads: they inherit it
  BarePingPong pong(domain, payload, BarePingPong::Role::kPong);
  int sig = 0;
  sigwait(&set, &sig);
  return 0;
}

std::vector<std::string> Words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// A whole number in [lo, hi] given to `flag`, else a message and exit 2 (atoi took "-1" for a
// size and "x" for 0: --evict -1 asked for 2^64 KiB).
size_t Count(const char* flag, const char* text, long long lo, long long hi) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) {
    std::cerr << "bench_pingpong: " << flag << " '" << text << "': want a whole number in " << lo << ".." << hi << "\n";
    std::exit(2);
  }
  return static_cast<size_t>(v);
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 20000, repeats = 5;
  size_t payload = 0, evict_kb = 0;
  bool processes = false, security = false;
  std::string only;  // "bare" or "dyad": that contender alone
  std::vector<std::string> pong_prefix;
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--processes")) processes = true;
    else if (!std::strcmp(argv[i], "--security")) security = true;
    else if (!std::strcmp(argv[i], "--bare-pong") && i + 2 < argc) return BarePongMain(std::atoi(argv[i + 1]), static_cast<size_t>(std::atoi(argv[i + 2])));
    else if (!has_value) {
      std::cerr << "bench_pingpong: " << argv[i] << ": unknown, or wants a value (see the top of bench_pingpong.cpp)\n";
      return 2;
    } else if (!std::strcmp(argv[i], "--rounds")) rounds = static_cast<int>(Count(argv[i], argv[i + 1], 10, 100'000'000)), ++i;
    else if (!std::strcmp(argv[i], "--repeats")) repeats = static_cast<int>(Count(argv[i], argv[i + 1], 1, 10'000)), ++i;
    else if (!std::strcmp(argv[i], "--payload")) payload = Count(argv[i], argv[i + 1], 0, 64 << 20), ++i;
    else if (!std::strcmp(argv[i], "--evict")) evict_kb = Count(argv[i], argv[i + 1], 0, 1 << 20), ++i;
    else if (!std::strcmp(argv[i], "--pong-prefix")) pong_prefix = Words(argv[++i]);
    else if (!std::strcmp(argv[i], "--only")) only = argv[++i];
    else {
      std::cerr << "bench_pingpong: " << argv[i] << ": unknown option (see the top of bench_pingpong.cpp)\n";
      return 2;
    }
  }
  if (!only.empty() && only != "bare" && only != "dyad") {
    std::cerr << "bench_pingpong: --only " << only << ": expected bare or dyad\n";
    return 2;
  }
  const bool run_bare = only != "dyad", run_dyad = only != "bare";
  const int domain = 1 + static_cast<int>(getpid() % 200);
  const std::string dir = std::filesystem::temp_directory_path() / ("dyad_pingpong_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::vector<int64_t> bare_all, dyad_all, secured_all;
  pid_t bare_pong = 0;
  if (processes) {
    const std::string self = std::filesystem::read_symlink("/proc/self/exe");
    bare_pong = Spawn(pong_prefix, {self, "--bare-pong", std::to_string(domain), std::to_string(payload)});
  }
  BarePingPong bare(domain, payload, processes ? BarePingPong::Role::kPing : BarePingPong::Role::kBoth, evict_kb);
  if (processes && !bare.WaitForPong(30)) {
    std::cerr << "bench_pingpong: the bare pong process did not match within 30 s\n";
    Stop(bare_pong);
    return 1;
  }
  if (run_bare) bare.Run(1000);        // warm-up
  for (int r = 0; r < repeats; ++r) {  // alternate, so drift on a shared machine hits both alike
    if (run_bare) {
      auto b = bare.Run(rounds);
      bare_all.insert(bare_all.end(), b.begin() + b.size() / 10, b.end());
    }
    if (!run_dyad) continue;
    auto d = RunDyad(domain + 1, rounds, payload, evict_kb, dir, processes, pong_prefix);
    dyad_all.insert(dyad_all.end(), d.begin() + d.size() / 10, d.end());
    if (security) {
      auto sec = RunDyad(domain + 1, rounds, payload, evict_kb, dir, processes, pong_prefix, true);
      secured_all.insert(secured_all.end(), sec.begin() + sec.size() / 10, sec.end());
    }
  }
  if (bare_pong != 0) Stop(bare_pong);
  std::filesystem::remove_all(dir);
  const double bm = Percentile(bare_all, 0.5), bp = Percentile(bare_all, 0.99);
  const double dm = Percentile(dyad_all, 0.5), dp = Percentile(dyad_all, 0.99);
  std::printf(
      "round trip, %s, RELIABLE KEEP_LAST 1, PingPong with %zu-byte payload, %d x %d rounds (first 10%% of each dropped)%s\n",
      processes ? (pong_prefix.empty() ? "two processes" : "two processes, pong behind the prefix") : "one process", payload,
      repeats, rounds, evict_kb > 0 ? (", " + std::to_string(evict_kb) + " KiB written before each").c_str() : "");
  const double ba = Mean(bare_all), da = Mean(dyad_all);
  std::printf("%-22s %12s %12s %12s\n", "", "median_us", "p99_us", "mean_us");
  if (run_bare) std::printf("%-22s %12.2f %12.2f %12.2f\n", "bare Fast DDS", bm, bp, ba);
  if (run_dyad) std::printf("%-22s %12.2f %12.2f %12.2f\n", "dyad components", dm, dp, da);
  if (run_bare && run_dyad) std::printf("%-22s %12.3f %12.3f %12.3f\n", "ratio dyad/bare", dm / bm, dp / bp, da / ba);
  std::printf("slow round trips (over twice the median):");
  if (run_bare) std::printf(" bare %.2f %%", SlowPercent(bare_all));
  if (run_dyad) std::printf("%s dyad %.2f %%", run_bare ? "," : "", SlowPercent(dyad_all));
  std::printf("\n");
  if (security) {
    const double sm = Percentile(secured_all, 0.5), sp = Percentile(secured_all, 0.99), sa = Mean(secured_all);
    std::printf("%-22s %12.2f %12.2f %12.2f\n", "dyad with security", sm, sp, sa);
    std::printf("%-22s %12.3f %12.3f %12.3f\n", "ratio secured/dyad", sm / dm, sp / dp, sa / da);
  }
  return 0;
}
