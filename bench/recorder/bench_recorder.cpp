// bench_recorder: how many small samples per second the recorder takes from 3 publishers with
// zero loss, and what it costs the publishers.
//
// Each case runs a real graph in this process (dyad::RunGraph): three `bench_burst` components
// publish `burst` Counter samples (~40 bytes of CDR) per step on t1, t2, t3, and, when recording,
// a `recorder` writes them to an MCAP file (zstd level 1, 256 KiB chunks). The recording is then
// read back: per topic, the count must equal what the publisher published (its steps x burst, from
// the run's timing table) and the sequence numbers must run 1..count; any difference is loss.
//   stepped: one thread steps the three publishers as fast as it can (--steps steps each).
//   wall:    three publisher threads at 100 Hz, each publishing --wall-burst per step, for --duration s.
// samples/s = recorded samples / wall time of the whole run (set-up and final drain included).
// The same graphs without the recorder give the publishers' own rate: the ratio is what recording
// costs them (intra-process delivery is synchronous, so the copy into the queue is on their time).
//
//   bench_recorder [--steps N] [--burst B] [--wall-burst B] [--duration S] [--repeats R] [--dir DIR]
// Defaults: 2000 steps of 100 samples per publisher (stepped: 600,000 samples); wall: 3000 samples
// per step per publisher at 100 Hz (offered: 900,000 samples/s) for 3 s; 3 repeats.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <dyad/mcap/reader.hpp>
#include <dyad/run.hpp>

namespace fs = std::filesystem;

namespace {

struct Case {
  std::string clock;  // "stepped" | "wall"
  bool record = true;
};

struct Result {
  double wall_s = 0;
  uint64_t published = 0, recorded = 0, lost = 0, payload_bytes = 0, file_bytes = 0;
  bool contiguous = true;
};

// Steps per component from RunGraph's timing table ("p1   1234   ...").
std::map<std::string, uint64_t> StepsFromReport(const std::string& report) {
  std::map<std::string, uint64_t> steps;
  std::istringstream in(report);
  std::string name;
  for (std::string line; std::getline(in, line);) {
    std::istringstream l(line);
    uint64_t n;
    if (l >> name >> n) steps[name] = n;
  }
  return steps;
}

Result RunCase(const Case& c, int steps, int burst, double duration, const fs::path& dir, int domain) {
  const fs::path graph = dir / "bench.yaml";
  const fs::path file = dir / "bench.mcap";
  fs::remove(file);
  std::ofstream g(graph);
  g << "graph: benchrec\nclock: " << c.clock << "\ndomain_id: " << domain << "\ncomponents:\n";
  for (int i = 1; i <= 3; ++i)
    g << "  p" << i << ": {type: bench_burst, rate_hz: 100, params: {burst: " << burst << "}, outputs: {out: t" << i << "}}\n";
  if (c.record) g << "  rec: {type: recorder, rate_hz: 1, params: {file: " << file.string() << ", overwrite: true, topics: [t1, t2, t3]}}\n";
  g.close();

  dyad::RunOptions o;
  o.graph_path = graph.string();
  o.plugin_paths = {DYAD_BENCH_PLUGIN};
  if (c.clock == "stepped") o.steps = static_cast<uint64_t>(steps);
  else o.duration_s = duration;
  std::ostringstream report, err;
  const auto t0 = std::chrono::steady_clock::now();
  const int code = dyad::RunGraph(o, report, err);
  Result r;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (code != 0) {
    std::cerr << "bench_recorder: dyad run failed (" << code << "):\n" << err.str();
    std::exit(1);
  }
  const auto table = StepsFromReport(report.str());
  std::map<std::string, uint64_t> published;
  const char* publishers[] = {"p1", "p2", "p3"};
  const char* topics[] = {"t1", "t2", "t3"};
  for (int i = 0; i < 3; ++i) {
    auto it = table.find(publishers[i]);
    const uint64_t n = it != table.end() ? it->second * static_cast<uint64_t>(burst) : 0;
    published[topics[i]] = n;
    r.published += n;
  }
  if (!c.record) return r;

  auto reader = dyad::mcap::Reader::Open(file.string());
  if (!reader.ok()) {
    std::cerr << "bench_recorder: " << reader.status().message() << "\n";
    std::exit(1);
  }
  r.file_bytes = fs::file_size(file);
  std::map<std::string, uint64_t> count;
  dyad::mcap::ReadOptions ro;
  ro.order = dyad::mcap::ReadOptions::Order::kFile;
  dyad::Status s = reader->ReadMessages(ro, [&](const dyad::mcap::MessageView& m) {
    uint64_t& n = count[m.channel->topic];
    if (m.sequence != static_cast<uint32_t>(n + 1)) r.contiguous = false;
    ++n;
    r.payload_bytes += m.data.size();
    return true;
  });
  if (!s.ok()) {
    std::cerr << "bench_recorder: " << s.message() << "\n";
    std::exit(1);
  }
  for (const auto& [topic, n] : published) {
    r.recorded += count[topic];
    r.lost += n > count[topic] ? n - count[topic] : 0;
    if (count[topic] > n) r.contiguous = false;  // more than published: the check itself is wrong
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  int steps = 2000, burst = 100, wall_burst = 3000, repeats = 3;
  double duration = 3.0;
  fs::path dir = fs::temp_directory_path() / ("dyad_bench_recorder_" + std::to_string(getpid()));
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--steps") steps = std::stoi(next());
    else if (a == "--burst") burst = std::stoi(next());
    else if (a == "--wall-burst") wall_burst = std::stoi(next());
    else if (a == "--duration") duration = std::stod(next());
    else if (a == "--repeats") repeats = std::stoi(next());
    else if (a == "--dir") dir = next();
    else {
      std::cerr << "usage: bench_recorder [--steps N] [--burst B] [--wall-burst B] [--duration S] [--repeats R] [--dir DIR]\n";
      return 2;
    }
  }
  fs::create_directories(dir);
  const int domain = 1 + static_cast<int>(getpid() % 200);
  std::printf("recorder throughput: 3 publishers; stepped: %d steps x %d samples each; wall: 100 Hz x %d samples each for %.1f s; "
              "%d repeats (median)\n", steps, burst, wall_burst, duration, repeats);
  std::printf("| clock | recorded samples | wall s | recorded samples/s | payload MB/s | file MB | lost | sequences | "
              "published/s without recorder | ratio |\n");
  std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: |\n");
  bool all_ok = true;
  for (const std::string clock : {"stepped", "wall"}) {
    std::vector<double> rate_rec, rate_base;
    Result last_rec;
    std::vector<Result> recs;
    for (int rep = 0; rep < repeats; ++rep) {
      const int b = clock == "wall" ? wall_burst : burst;
      Result base = RunCase({clock, false}, steps, b, duration, dir, domain);
      Result rec = RunCase({clock, true}, steps, b, duration, dir, domain);
      rate_base.push_back(static_cast<double>(base.published) / base.wall_s);
      rate_rec.push_back(static_cast<double>(rec.recorded) / rec.wall_s);
      recs.push_back(rec);
      if (rec.lost != 0 || !rec.contiguous) all_ok = false;
    }
    auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    // The repeat whose rate is the median, for its other columns.
    const double med = median(rate_rec);
    for (size_t i = 0; i < recs.size(); ++i)
      if (static_cast<double>(recs[i].recorded) / recs[i].wall_s == med) last_rec = recs[i];
    uint64_t lost = 0;
    bool contiguous = true;
    for (const auto& r : recs) lost += r.lost, contiguous = contiguous && r.contiguous;
    std::printf("| %s | %llu | %.2f | %.0f | %.2f | %.2f | %llu | %s | %.0f | %.2f |\n", clock.c_str(),
                static_cast<unsigned long long>(last_rec.recorded), last_rec.wall_s, med,
                static_cast<double>(last_rec.payload_bytes) / 1e6 / last_rec.wall_s, static_cast<double>(last_rec.file_bytes) / 1e6,
                static_cast<unsigned long long>(lost), contiguous ? "contiguous" : "GAPS", median(rate_base), med / median(rate_base));
  }
  fs::remove_all(dir);
  std::printf("%s\n", all_ok ? "zero loss in every run" : "LOSS DETECTED");
  return all_ok ? 0 : 1;
}
