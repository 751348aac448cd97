#include "dyad/observer/observer_file.hpp"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace dyad::observer {
namespace {

using nlohmann::json;
constexpr char kMagic[8] = {'D', 'Y', 'A', 'D', 'O', 'B', 'S', 'V'};
constexpr size_t kFixedHeader = 8 + 4 + 4 + 8;
constexpr size_t kTrailer = 4;

template <typename T>
void Put(std::string& out, T v) {
  for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<char>((static_cast<uint64_t>(v) >> (8 * i)) & 0xff));
}

template <typename T>
T Get(const std::string& in, size_t at) {
  uint64_t v = 0;
  for (size_t i = 0; i < sizeof(T); ++i) v |= static_cast<uint64_t>(static_cast<unsigned char>(in[at + i])) << (8 * i);
  return static_cast<T>(v);
}

uint32_t Crc(const char* data, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (n > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(data), chunk);
    data += chunk;
    n -= chunk;
  }
  return static_cast<uint32_t>(crc);
}

json Num(double v) { return std::isnan(v) ? json(nullptr) : json(v); }
double NumFrom(const json& j) { return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>(); }

}  // namespace

Status SaveObserver(const ObserverFile& observer, const std::string& path) {
  const ClassifierSpec& s = observer.classifier.spec();
  json workspace = json::array();
  for (const auto& r : s.workspace) workspace.push_back({r.min, r.max});
  const auto& p = observer.provenance;
  const Eigen::VectorXd& params = observer.classifier.parameters();
  const json header = {
      {"format", "dyad observer"},
      {"spec",
       {{"window", s.window}, {"hidden", s.hidden}, {"classes", s.classes}, {"input", ToString(s.input)},
        {"workspace", workspace}}},
      {"parameters", params.size()},
      {"provenance",
       {{"source", p.source}, {"model", p.model}, {"train_seeds", p.train_seeds},
        {"validation_seeds", p.validation_seeds}, {"steps", p.steps}, {"drop", p.drop}, {"epochs", p.epochs},
        {"seed", p.seed}, {"validation_min_diagonal", Num(p.validation_min_diagonal)},
        {"validation_accuracy", Num(p.validation_accuracy)}}},
  };
  const std::string js = header.dump(1);
  std::string out;
  out.reserve(kFixedHeader + js.size() + static_cast<size_t>(params.size()) * 8 + kTrailer);
  out.append(kMagic, 8);
  Put<uint32_t>(out, kObserverFileVersion);
  Put<uint32_t>(out, 0);
  Put<uint64_t>(out, js.size());
  out += js;
  for (Eigen::Index i = 0; i < params.size(); ++i) {
    uint64_t bits;
    std::memcpy(&bits, &params(i), 8);
    Put<uint64_t>(out, bits);
  }
  Put<uint32_t>(out, Crc(out.data(), out.size()));

  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return Status::IOError(path + ": cannot open " + tmp + " for writing");
    f.write(out.data(), static_cast<std::streamsize>(out.size()));
    f.flush();
    if (!f) return Status::IOError(path + ": write failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return Status::IOError(path + ": cannot rename " + tmp + ": " + ec.message());
  return Status::OK();
}

StatusOr<ObserverFile> LoadObserver(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Status::InvalidArgument(path + ": is a folder, not an observer file");
  std::ifstream f(path, std::ios::binary);
  if (!f) return Status::NotFound(path + ": cannot open");
  std::string in;
  try {
    in.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {
    return Status::IOError(path + ": read failed: " + e.what());
  }
  if (in.size() < 8 || std::memcmp(in.data(), kMagic, 8) != 0)
    return Status::DataLoss(path + ": not a dyad observer file (bad magic)");
  if (in.size() < kFixedHeader + kTrailer)
    return Status::DataLoss(path + ": truncated: " + std::to_string(in.size()) + " bytes, less than the fixed header");
  const uint32_t version = Get<uint32_t>(in, 8);
  if (version != kObserverFileVersion)
    return Status::Unimplemented(path + ": format version " + std::to_string(version) + ", this build reads version " +
                                 std::to_string(kObserverFileVersion));
  const uint64_t jlen = Get<uint64_t>(in, 16);
  if (jlen > in.size() - kFixedHeader - kTrailer)
    return Status::DataLoss(path + ": truncated: header of " + std::to_string(jlen) + " bytes does not fit in " +
                            std::to_string(in.size()) + " bytes");
  if (Get<uint32_t>(in, in.size() - kTrailer) != Crc(in.data(), in.size() - kTrailer))
    return Status::DataLoss(path + ": corrupted or truncated (checksum mismatch)");
  const size_t payload_at = kFixedHeader + jlen;
  const size_t payload_bytes = in.size() - kTrailer - payload_at;
  ObserverFile out;
  ClassifierSpec spec;
  try {
    const json header = json::parse(in.begin() + kFixedHeader, in.begin() + static_cast<std::ptrdiff_t>(payload_at));
    const json& s = header.at("spec");
    spec.window = s.at("window").get<int>();
    spec.hidden = s.at("hidden").get<std::vector<int>>();
    spec.classes = s.at("classes").get<int>();
    const std::string input = s.at("input").get<std::string>();
    if (!ParseInputRepresentation(input, &spec.input))
      return Status::DataLoss(path + ": spec.input: unknown representation \"" + input + "\"");
    spec.workspace.clear();
    for (const auto& r : s.at("workspace")) spec.workspace.push_back({r.at(0).get<double>(), r.at(1).get<double>()});
    const auto& p = header.at("provenance");
    auto& pv = out.provenance;
    pv.source = p.at("source").get<std::string>();
    pv.model = p.at("model").get<std::string>();
    pv.train_seeds = p.at("train_seeds").get<std::vector<uint64_t>>();
    pv.validation_seeds = p.at("validation_seeds").get<std::vector<uint64_t>>();
    pv.steps = p.at("steps").get<int>();
    pv.drop = p.at("drop").get<int>();
    pv.epochs = p.at("epochs").get<int>();
    pv.seed = p.at("seed").get<uint64_t>();
    pv.validation_min_diagonal = NumFrom(p.at("validation_min_diagonal"));
    pv.validation_accuracy = NumFrom(p.at("validation_accuracy"));
    if (Status st = spec.Validate(); !st.ok()) return Status::DataLoss(path + ": spec." + st.message());
    const int64_t count = header.at("parameters").get<int64_t>();
    if (count != spec.num_parameters())
      return Status::DataLoss(path + ": header lists " + std::to_string(count) + " parameters, the spec needs " +
                              std::to_string(spec.num_parameters()));
  } catch (const std::exception& e) {
    return Status::DataLoss(path + ": unreadable header: " + e.what());
  }
  const int64_t n = spec.num_parameters();
  if (payload_bytes != static_cast<size_t>(n) * 8)
    return Status::DataLoss(path + ": payload has " + std::to_string(payload_bytes) + " bytes, the spec needs " +
                            std::to_string(n * 8));
  Eigen::VectorXd params(n);
  for (int64_t i = 0; i < n; ++i) {
    const uint64_t bits = Get<uint64_t>(in, payload_at + static_cast<size_t>(i) * 8);
    std::memcpy(&params(i), &bits, 8);
    if (!std::isfinite(params(i))) return Status::DataLoss(path + ": parameter " + std::to_string(i) + " is not finite");
  }
  auto c = Classifier::FromParameters(spec, std::move(params));
  if (!c.ok()) return Status::DataLoss(path + ": " + c.status().message());
  out.classifier = std::move(c.value());
  return out;
}

}  // namespace dyad::observer
