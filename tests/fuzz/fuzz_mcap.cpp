// Fuzz target: the MCAP reader on the `dyad bag info` path (summary, or the linear scan of a file
// cut short), then every message read back as `dyad bag export` does. The first byte chooses
// summary or forced scan; the rest is the file.
#include <cstdio>

#include "bag_info.hpp"
#include "dyad/mcap/reader.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  dyad::mcap::ReaderOptions options;
  options.use_summary = (data[0] & 1) == 0;
  const std::string path = dyad::fuzz::WriteTemp(data + 1, size - 1, "bag.mcap");
  auto reader = dyad::mcap::Reader::Open(path, options);
  if (!reader.ok()) {
    dyad::fuzz::Require(reader.status().message().find(path) != std::string::npos, reader.status().ToString());
  } else {
    (void)dyad::bag::FormatInfo(*reader);
    dyad::mcap::ReadOptions read;
    read.skip_damaged = (data[0] & 2) != 0;
    read.order = (data[0] & 4) ? dyad::mcap::ReadOptions::Order::kFile : dyad::mcap::ReadOptions::Order::kLogTime;
    size_t bytes = 0;
    dyad::Status s = reader->ReadMessages(read, [&](const dyad::mcap::MessageView& m) {
      bytes += m.data.size();
      return true;
    });
    if (!s.ok()) dyad::fuzz::Require(s.message().find(path) != std::string::npos, s.ToString());
    (void)reader->VerifyDataCrc();
  }
  std::remove(path.c_str());
  return 0;
}
