#include "dyad/observer/observer_file.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "dyad/pvrnn/checked_file.hpp"
#include "dyad/pvrnn/json_fields.hpp"

namespace dyad::observer {
namespace {

using nlohmann::json;
constexpr char kMagic[8] = {'D', 'Y', 'A', 'D', 'O', 'B', 'S', 'V'};

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
  std::string out = pvrnn::BeginCheckedFile(kMagic, kObserverFileVersion, header.dump(1));
  out.reserve(out.size() + static_cast<size_t>(params.size()) * 8 + 4);
  for (Eigen::Index i = 0; i < params.size(); ++i) pvrnn::AppendDouble(out, params(i));
  return pvrnn::FinishCheckedFile(out, path);
}

StatusOr<ObserverFile> LoadObserver(const std::string& path) {
  auto bytes = pvrnn::ReadWholeFile(path, "observer file");
  if (!bytes.ok()) return bytes.status();
  const std::string& in = *bytes;
  auto view = pvrnn::OpenCheckedFile(in, path, kMagic, kObserverFileVersion, "dyad observer file");
  if (!view.ok()) return view.status();
  if (!view->crc_ok) return Status::DataLoss(path + ": corrupted or truncated (checksum mismatch)");
  const size_t payload_at = view->payload_at;
  const size_t payload_bytes = view->payload_bytes;
  ObserverFile out;
  ClassifierSpec spec;
  try {
    const json header = json::parse(view->json);
    const json& s = header.at("spec");
    spec.window = pvrnn::JsonInt<int>(s, "window");
    spec.hidden = pvrnn::JsonIntArray<int>(s, "hidden");
    spec.classes = pvrnn::JsonInt<int>(s, "classes");
    const std::string input = s.at("input").get<std::string>();
    if (!ParseInputRepresentation(input, &spec.input))
      return Status::DataLoss(path + ": spec.input: unknown representation \"" + input + "\"");
    spec.workspace.clear();
    for (const auto& r : s.at("workspace")) spec.workspace.push_back({r.at(0).get<double>(), r.at(1).get<double>()});
    const auto& p = header.at("provenance");
    auto& pv = out.provenance;
    pv.source = p.at("source").get<std::string>();
    pv.model = p.at("model").get<std::string>();
    pv.train_seeds = pvrnn::JsonIntArray<uint64_t>(p, "train_seeds");
    pv.validation_seeds = pvrnn::JsonIntArray<uint64_t>(p, "validation_seeds");
    pv.steps = pvrnn::JsonInt<int>(p, "steps");
    pv.drop = pvrnn::JsonInt<int>(p, "drop");
    pv.epochs = pvrnn::JsonInt<int>(p, "epochs");
    pv.seed = pvrnn::JsonInt<uint64_t>(p, "seed");
    pv.validation_min_diagonal = NumFrom(p.at("validation_min_diagonal"));
    pv.validation_accuracy = NumFrom(p.at("validation_accuracy"));
    if (Status st = spec.Validate(); !st.ok()) return Status::DataLoss(path + ": spec." + st.message());
    const int64_t count = pvrnn::JsonInt<int64_t>(header, "parameters");
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
    params(i) = pvrnn::ReadDouble(in, payload_at + static_cast<size_t>(i) * 8);
    if (!std::isfinite(params(i))) return Status::DataLoss(path + ": parameter " + std::to_string(i) + " is not finite");
  }
  auto c = Classifier::FromParameters(spec, std::move(params));
  if (!c.ok()) return Status::DataLoss(path + ": " + c.status().message());
  out.classifier = std::move(c.value());
  return out;
}

}  // namespace dyad::observer
