#include "dyad/pvrnn/checked_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace dyad::pvrnn {
namespace {

constexpr size_t kFixedHeader = 8 + 4 + 4 + 8;
constexpr size_t kTrailer = 4;

template <typename T>
void Put(std::string& out, T v) {
  unsigned char b[sizeof(T)];
  for (size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<unsigned char>((static_cast<uint64_t>(v) >> (8 * i)) & 0xff);
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

template <typename T>
T Get(const std::string& in, size_t at) {
  uint64_t v = 0;
  for (size_t i = 0; i < sizeof(T); ++i) v |= static_cast<uint64_t>(static_cast<unsigned char>(in[at + i])) << (8 * i);
  return static_cast<T>(v);
}

uint32_t Crc(const char* data, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (n > 0) {  // zlib takes uInt lengths
    const uInt chunk = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(data), chunk);
    data += chunk;
    n -= chunk;
  }
  return static_cast<uint32_t>(crc);
}

}  // namespace

std::string BeginCheckedFile(const char (&magic)[8], uint32_t version, std::string_view json) {
  std::string out;
  out.reserve(kFixedHeader + json.size() + kTrailer);
  out.append(magic, 8);
  Put<uint32_t>(out, version);
  Put<uint32_t>(out, 0);
  Put<uint64_t>(out, json.size());
  out.append(json);
  return out;
}

Status FinishCheckedFile(std::string& bytes, const std::string& path) {
  Put<uint32_t>(bytes, Crc(bytes.data(), bytes.size()));
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return Status::IOError(path + ": cannot open " + tmp + " for writing");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) return Status::IOError(path + ": write failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return Status::IOError(path + ": cannot rename " + tmp + ": " + ec.message());
  return Status::OK();
}

void AppendDouble(std::string& bytes, double value) {
  uint64_t bits;
  std::memcpy(&bits, &value, 8);
  Put<uint64_t>(bytes, bits);
}

double ReadDouble(const std::string& bytes, size_t at) {
  const uint64_t bits = Get<uint64_t>(bytes, at);
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

StatusOr<std::string> ReadWholeFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Status::InvalidArgument(path + ": is a folder, not a " + what);
  std::ifstream f(path, std::ios::binary);
  if (!f) return Status::NotFound(path + ": cannot open");
  std::string in;
  try {
    in.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {  // libstdc++ throws on a read error
    return Status::IOError(path + ": read failed: " + e.what());
  }
  return in;
}

StatusOr<CheckedFileView> OpenCheckedFile(const std::string& in, const std::string& path, const char (&magic)[8],
                                          uint32_t version, const std::string& kind) {
  if (in.size() < 8 || std::memcmp(in.data(), magic, 8) != 0)
    return Status::DataLoss(path + ": not a " + kind + " (bad magic)");
  if (in.size() < kFixedHeader + kTrailer)
    return Status::DataLoss(path + ": truncated: " + std::to_string(in.size()) + " bytes, less than the fixed header");
  const uint32_t stored_version = Get<uint32_t>(in, 8);
  if (stored_version != version)
    return Status::Unimplemented(path + ": format version " + std::to_string(stored_version) +
                                 ", this build reads version " + std::to_string(version));
  const uint64_t jlen = Get<uint64_t>(in, 16);
  if (jlen > in.size() - kFixedHeader - kTrailer)
    return Status::DataLoss(path + ": truncated: header of " + std::to_string(jlen) + " bytes does not fit in " +
                            std::to_string(in.size()) + " bytes");
  CheckedFileView v;
  v.json = std::string_view(in).substr(kFixedHeader, jlen);
  v.payload_at = kFixedHeader + jlen;
  v.payload_bytes = in.size() - kTrailer - v.payload_at;
  v.crc_ok = Get<uint32_t>(in, in.size() - kTrailer) == Crc(in.data(), in.size() - kTrailer);
  return v;
}

}  // namespace dyad::pvrnn
