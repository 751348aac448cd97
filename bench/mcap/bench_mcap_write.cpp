// Writer throughput for the recorder's case: small (48-byte) CDR samples from 3 channels.
//
//   bench_mcap_write [SAMPLES] [DIR]     (defaults: 3000000, /tmp)
//
// For each writer configuration: samples/s, payload MB/s, file size, and the ratio to plain
// fwrite(3) of the same payload bytes measured in the same run (the floor any recorder pays).
// Also: CRC32 speed of zlib's crc32_z against a byte-at-a-time table (why dyad_mcap uses zlib).
// The recorder's target is >= 100,000 samples/s without loss; the writer alone must be far above.
#include <zlib.h>

#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "dyad/mcap/writer.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kPayload = 48;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

// A plausible 48-byte CDR sample (little endian): encapsulation header, then the body of
// `struct Sample { unsigned long long stamp_ns; double v[4]; unsigned long counter; }`, 4 slowly
// varying doubles.
void MakeSample(std::uint64_t i, std::uint8_t* out) {
  const std::uint8_t header[4] = {0x00, 0x01, 0x00, 0x00};
  std::memcpy(out, header, 4);
  const std::uint64_t stamp = 1'700'000'000'000'000'000ull + i * 10'000;
  std::memcpy(out + 4, &stamp, 8);
  for (int k = 0; k < 4; ++k) {
    const double v = 100.0 * k + 0.001 * static_cast<double>(i % 100000) * (k + 1);
    std::memcpy(out + 12 + 8 * k, &v, 8);
  }
  const auto counter = static_cast<std::uint32_t>(i);
  std::memcpy(out + 44, &counter, 4);
}

struct Result {
  double seconds = 0;
  std::uint64_t file_bytes = 0;
};

Result RunFwrite(const std::string& path, std::uint64_t samples) {
  std::uint8_t sample[kPayload];
  const auto start = Clock::now();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::exit(1);
  for (std::uint64_t i = 0; i < samples; ++i) {
    MakeSample(i, sample);
    if (std::fwrite(sample, 1, kPayload, f) != kPayload) std::exit(1);
  }
  std::fclose(f);
  Result r{Seconds(start), std::filesystem::file_size(path)};
  std::filesystem::remove(path);
  return r;
}

Result RunMcap(const std::string& path, std::uint64_t samples, const dyad::mcap::WriterOptions& options) {
  std::uint8_t sample[kPayload];
  const auto start = Clock::now();
  auto writer = dyad::mcap::Writer::Open(path, options);
  if (!writer.ok()) {
    std::fprintf(stderr, "%s\n", writer.status().ToString().c_str());
    std::exit(1);
  }
  // The IDL that MakeSample's bytes follow, so `dyad bag export` decodes a kept bench file.
  auto schema = writer->AddSchema("dyad::bench::Sample", "omgidl",
                                  "module dyad { module bench { struct Sample {\n"
                                  "  unsigned long long stamp_ns; double v[4]; unsigned long counter;\n"
                                  "}; }; };\n");
  dyad::mcap::ChannelId channels[3];
  for (int c = 0; c < 3; ++c) channels[c] = *writer->AddChannel("/bench/" + std::to_string(c), "cdr", *schema);
  std::uint32_t sequence[3] = {};
  for (std::uint64_t i = 0; i < samples; ++i) {
    MakeSample(i, sample);
    const int c = static_cast<int>(i % 3);
    const std::uint64_t t = 1'700'000'000'000'000'000ull + i * 3'333;
    dyad::Status s = writer->Write(channels[c], sequence[c]++, t, t - 1000, sample);
    if (!s.ok()) {
      std::fprintf(stderr, "%s\n", s.ToString().c_str());
      std::exit(1);
    }
  }
  if (dyad::Status s = writer->Close(); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.ToString().c_str());
    std::exit(1);
  }
  Result r{Seconds(start), std::filesystem::file_size(path)};
  std::filesystem::remove(path);
  return r;
}

std::uint32_t BytewiseCrc32(const std::uint8_t* p, std::size_t n) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void BenchCrc() {
  std::vector<std::uint8_t> data(64 << 20);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 2654435761u >> 13);
  auto start = Clock::now();
  const auto a = static_cast<std::uint32_t>(crc32_z(0, data.data(), data.size()));
  const double zlib_s = Seconds(start);
  start = Clock::now();
  const std::uint32_t b = BytewiseCrc32(data.data(), data.size());
  const double table_s = Seconds(start);
  std::printf("crc32 of 64 MiB: zlib crc32_z %.2f GB/s, byte table %.2f GB/s (%s)\n", data.size() / zlib_s / 1e9,
              data.size() / table_s / 1e9, a == b ? "same result" : "RESULTS DIFFER");
}

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t samples = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 3'000'000;
  const std::string dir = argc > 2 ? argv[2] : "/tmp";
  const std::string path = dir + "/bench_mcap_write." + std::to_string(::getpid());
  std::printf("%llu samples of %zu bytes from 3 channels; files in %s\n",
              static_cast<unsigned long long>(samples), kPayload, dir.c_str());

  RunFwrite(path, samples / 10);  // Warm the page cache and the CPU.
  const Result base = RunFwrite(path, samples);
  const double payload_mb = samples * kPayload / 1e6;
  std::printf("%-28s %12s %10s %12s %10s\n", "writer", "samples/s", "MB/s", "file MB", "vs fwrite");
  std::printf("%-28s %12.0f %10.1f %12.1f %10s\n", "fwrite (payload only)", samples / base.seconds,
              payload_mb / base.seconds, base.file_bytes / 1e6, "1.00");

  struct Config {
    const char* name;
    dyad::mcap::Compression compression;
    int level;
    std::uint64_t chunk_size;
  };
  const Config configs[] = {
      {"mcap zstd-1 256KiB (default)", dyad::mcap::Compression::kZstd, 1, 256 << 10},
      {"mcap zstd-1 64KiB", dyad::mcap::Compression::kZstd, 1, 64 << 10},
      {"mcap zstd-1 1MiB", dyad::mcap::Compression::kZstd, 1, 1 << 20},
      {"mcap zstd-3 256KiB", dyad::mcap::Compression::kZstd, 3, 256 << 10},
      {"mcap none 256KiB", dyad::mcap::Compression::kNone, 1, 256 << 10},
  };
  for (const Config& c : configs) {
    dyad::mcap::WriterOptions options;
    options.compression = c.compression;
    options.zstd_level = c.level;
    options.chunk_size = c.chunk_size;
    options.replace_existing = true;  // one scratch path for every configuration
    const Result r = RunMcap(path, samples, options);
    std::printf("%-28s %12.0f %10.1f %12.1f %10.2f\n", c.name, samples / r.seconds, payload_mb / r.seconds,
                r.file_bytes / 1e6, base.seconds / r.seconds);
  }
  BenchCrc();
  return 0;
}
