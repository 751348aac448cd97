// Writes the seed corpora of the fuzz targets whose inputs are files dyad writes itself, with
// dyad's own writers (so seeds follow the formats as they change): run at build time as
//   dyad_fuzz_make_seeds CORPUS_DIR
// giving CORPUS_DIR/<target>/<seed>. Graph, IDL and --set seeds are copied by CMake instead.
#include <array>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>
#include <fastdds/dds/topic/TopicDataType.hpp>

#include <dyad/msg/types.hpp>

#include "dyad/mcap/writer.hpp"
#include "dyad/observer/observer_file.hpp"
#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/model_file.hpp"
#include "udp_protocol.hpp"

namespace fs = std::filesystem;

namespace {

fs::path g_root;

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void Seed(const std::string& target, const std::string& name, const std::string& bytes) {
  fs::create_directories(g_root / target);
  std::ofstream(g_root / target / name, std::ios::binary) << bytes;
}

void Check(const dyad::Status& s, const std::string& what) {
  if (s.ok()) return;
  std::cerr << "dyad_fuzz_make_seeds: " << what << ": " << s.ToString() << "\n";
  std::exit(1);
}

void ModelSeeds(const fs::path& work) {
  dyad::pvrnn::ModelSpec spec = dyad::pvrnn::ModelSpec::MacawBot();
  spec.layers[0].d = 6;
  spec.layers[1].d = 3;
  dyad::pvrnn::Model m = dyad::pvrnn::Model::Initialize(spec, 5, 2, 42);
  const fs::path path = work / "small.dpvrnn";
  Check(dyad::pvrnn::SaveModel(m, path.string()), "model");
  Seed("model_file", "small.dpvrnn", "\x01" + ReadAll(path));  // 1: harness keeps the CRC right
  dyad::pvrnn::TrainingState st;
  st.adam_step = 7;
  st.weights_m = Eigen::VectorXd::Zero(m.weights.flat().size());
  st.weights_v = Eigen::VectorXd::Zero(m.weights.flat().size());
  st.adaptive_m = Eigen::VectorXd::Zero(m.adaptive.flat().size());
  st.adaptive_v = Eigen::VectorXd::Zero(m.adaptive.flat().size());
  st.rng_state = "1 2 3";
  m.training = st;
  Check(dyad::pvrnn::SaveModel(m, path.string()), "model with training state");
  Seed("model_file", "training.dpvrnn", "\x01" + ReadAll(path));
}

void ObserverSeeds(const fs::path& work) {
  dyad::observer::ClassifierSpec s;
  s.window = 3;
  s.hidden = {5, 4};
  s.classes = 3;
  s.workspace = {{-50, 50}, {-50, 50}};
  dyad::observer::ObserverFile f;
  auto c = dyad::observer::Classifier::Create(s, 2);
  Check(c.status(), "classifier");
  f.classifier = *c;
  f.provenance.source = "seed";
  f.provenance.train_seeds = {1, 2};
  const fs::path path = work / "small.dobs";
  Check(dyad::observer::SaveObserver(f, path.string()), "observer");
  Seed("observer_file", "small.dobs", "\x01" + ReadAll(path));
}

// The first byte of an MCAP seed is the harness's option byte (bit 0: force the scan).
void McapSeeds(const fs::path& work) {
  for (auto compression : {dyad::mcap::Compression::kZstd, dyad::mcap::Compression::kNone}) {
    const bool zstd = compression == dyad::mcap::Compression::kZstd;
    const fs::path path = work / "seed.mcap";
    dyad::mcap::WriterOptions options;
    options.chunk_size = 1024;
    options.compression = compression;
    options.replace_existing = true;  // the same work file for each compression
    auto w = dyad::mcap::Writer::Open(path.string(), options);
    Check(w.status(), "mcap open");
    const dyad::TypeInfo* type = dyad::msg::AllTypes().front();
    auto schema = w->AddSchema(type->name, "omgidl", type->idl);
    Check(schema.status(), "mcap schema");
    auto a = w->AddChannel("human/input", "cdr", *schema, {{"qos", "reliable"}});
    auto b = w->AddChannel("robot/state", "cdr", *schema, {});
    Check(a.status(), "mcap channel");
    Check(b.status(), "mcap channel");
    Check(w->AddMetadata("dyad.graph", {{"yaml", "graph: seed\n"}}), "mcap metadata");
    for (uint32_t i = 0; i < 40; ++i) {
      std::array<uint8_t, 24> sample{0, 1, 0, 0};
      sample[4] = static_cast<uint8_t>(i);
      Check(w->Write(i % 2 ? *a : *b, i, 1000 + i, 900 + i, sample), "mcap write");
    }
    Check(w->Close(), "mcap close");
    const std::string bytes = ReadAll(path);
    const std::string tag = zstd ? "zstd" : "plain";
    Seed("mcap", tag + "_summary.mcap", std::string(1, '\0') + bytes);
    Seed("mcap", tag + "_scan.mcap", std::string(1, '\1') + bytes);
    Seed("mcap", tag + "_cut.mcap", std::string(1, '\0') + bytes.substr(0, bytes.size() * 3 / 5));
  }
}

void CdrSeeds() {
  const auto types = dyad::msg::AllTypes();
  auto short_name = [](const std::string& name) { return name.substr(name.rfind(':') + 1); };
  for (size_t i = 0; i < types.size(); ++i) {
    std::unique_ptr<eprosima::fastdds::dds::TopicDataType> support(types[i]->make_type_support());
    void* sample = support->createData();
    eprosima::fastrtps::rtps::SerializedPayload_t payload(support->getSerializedSizeProvider(sample)());
    if (!support->serialize(sample, &payload)) {
      std::cerr << "dyad_fuzz_make_seeds: cannot serialize " << types[i]->name << "\n";
      std::exit(1);
    }
    support->deleteData(sample);
    Seed("cdr_decode", short_name(types[i]->name) + ".cdr",
         std::string(1, static_cast<char>(i)) + std::string(reinterpret_cast<const char*>(payload.data), payload.length));
    Seed("cdr_schema", short_name(types[i]->name) + ".idl", types[i]->idl);
  }
  // dyad_cdr_test::Everything (the harness's last type): all zeros is a valid sample of it
  // (empty strings and sequences, first enumerators).
  std::string everything(1, static_cast<char>(types.size()));
  everything += std::string("\0\1\0\0", 4) + std::string(400, '\0');
  Seed("cdr_decode", "Everything.cdr", everything);
}

void UdpSeeds() {
  namespace udp = dyad::cartesian::udp;
  udp::CommandPacket c;
  c.session = 7;
  c.sequence = 3;
  c.x = 1.5;
  c.hold = true;
  std::array<uint8_t, udp::kCommandSize> cb{};
  udp::Encode(c, cb);
  Seed("udp_protocol", "command.bin", std::string(cb.begin(), cb.end()));
  udp::StatePacket s;
  s.session = 7;
  s.ack = 3;
  s.vx = -2;
  std::array<uint8_t, udp::kStateSize> sb{};
  udp::Encode(s, sb);
  Seed("udp_protocol", "state.bin", std::string(sb.begin(), sb.end()));
}

void DatasetSeeds(const fs::path& work) {
  dyad::pvrnn::Dataset data = dyad::pvrnn::MakeAnalyticDataset();
  data.sequences.resize(3);
  for (auto& s : data.sequences) s = s.leftCols(12).eval();
  const fs::path dir = work / "analytic";
  Check(dyad::pvrnn::WriteNrlDataset(data, dir.string()), "dataset");
  std::string packed = ReadAll(dir / "dataset.d");
  for (int p = 0; p < data.size(); ++p) packed += "\n----\n" + ReadAll(dir / ("primitive_" + std::to_string(p) + "_0.csv"));
  Seed("dataset", "analytic", packed);
  Seed("nrl_text", "dataset.d", ReadAll(dir / "dataset.d"));
  Seed("nrl_text", "primitive.csv", ReadAll(dir / "primitive_0_0.csv"));
  Seed("nrl_text", "properties.d",
       "# MacawBot\nd=40,10\nz=4,1\nt=2,10\nw=0.01,0.01\nsigma=0.5\nactivejoints=2\nepochs=50000\nalpha=0.001\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: dyad_fuzz_make_seeds CORPUS_DIR\n";
    return 2;
  }
  g_root = argv[1];
  const fs::path work = g_root / ".work";
  fs::create_directories(work);
  ModelSeeds(work);
  ObserverSeeds(work);
  McapSeeds(work);
  CdrSeeds();
  UdpSeeds();
  DatasetSeeds(work);
  fs::remove_all(work);
  return 0;
}
