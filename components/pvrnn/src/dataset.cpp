#include "dyad/pvrnn/dataset.hpp"

#include <filesystem>
#include <fstream>

#include "dyad/pvrnn/nrl_import.hpp"
#include "nrl_text.hpp"

namespace dyad::pvrnn {
namespace fs = std::filesystem;

namespace {

// names.txt, when there is one (dataset.hpp: its rules).
Status ReadNames(const std::string& dir, Dataset* data) {
  const std::string file = (fs::path(dir) / "names.txt").string();
  std::ifstream in(file);
  if (!in) return fs::exists(file) ? Status::IOError(file + ": cannot open") : Status::OK();
  std::vector<std::string> names;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = file + ":" + std::to_string(line_no) + ": ";
    if (line.empty() && in.peek() == EOF) break;  // a last line that only ends the file
    if (line.empty() || line.size() > 40) return Status::DataLoss(where + "a name is 1 to 40 bytes, got " + std::to_string(line.size()));
    for (unsigned char c : line)
      if (c < 0x20 || c == 0x7f) return Status::DataLoss(where + "a name holds no control characters");
    for (size_t k = 0; k < names.size(); ++k)
      if (names[k] == line) return Status::DataLoss(where + "'" + line + "' names primitive " + std::to_string(k) + " already");
    names.push_back(line);
  }
  if (names.size() != data->sequences.size())
    return Status::DataLoss(file + ": " + std::to_string(names.size()) + " names, dataset.d says numberprims=" +
                            std::to_string(data->sequences.size()));
  data->names = std::move(names);
  return Status::OK();
}

}  // namespace

StatusOr<Dataset> LoadNrlDataset(const std::string& dir) {
  const std::string meta = (fs::path(dir) / "dataset.d").string();
  auto kv = ReadKeyValueFile(meta);
  if (!kv.ok()) return kv.status();
  Dataset data;
  data.name = fs::path(dir).filename().string();
  if (data.name.empty()) data.name = fs::path(dir).parent_path().filename().string();
  int64_t steps = -1, prims = -1;
  for (const auto& entry : kv.value()) {
    const std::string& k = entry.first;  // not a structured binding: clang 14 cannot capture one
    const std::string& v = entry.second;
    auto bad = [&](const char* rule) { return Status::DataLoss(meta + ": " + k + " = '" + v + "': " + rule); };
    std::vector<double> period;
    if (k == "samplingperiod" && !(internal::ParseNumberList(v, &period) && period.size() == 1 && period[0] > 0))
      return bad("must be a number > 0");
    if (k == "samplingperiod") data.sampling_period_ms = period[0];
    if (k == "numbertimes" && !internal::ParseInteger(v, 1, 10'000'000, &steps))
      return bad("must be a whole number in 1..10000000");
    if (k == "numberprims" && !internal::ParseInteger(v, 1, 100'000, &prims))
      return bad("must be a whole number in 1..100000");
  }
  if (steps <= 0) return Status::DataLoss(meta + ": numbertimes missing");
  if (prims <= 0) return Status::DataLoss(meta + ": numberprims missing");
  std::vector<double> row;
  for (int p = 0; p < prims; ++p) {
    const std::string file = (fs::path(dir) / ("primitive_" + std::to_string(p) + "_0.csv")).string();
    std::ifstream in(file);
    if (!in) return Status::NotFound(file + ": cannot open (dataset.d lists " + std::to_string(prims) + " primitives)");
    std::vector<std::vector<double>> rows;
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      if (std::string bad; !internal::ParseNumberList(line, &row, &bad))
        return Status::DataLoss(file + ":" + std::to_string(line_no) + ": '" + bad +
                                "' is not a finite number (expected a comma-separated row of numbers)");
      if (!rows.empty() && row.size() != rows[0].size())
        return Status::DataLoss(file + ":" + std::to_string(line_no) + ": " + std::to_string(row.size()) +
                                 " values, earlier rows have " + std::to_string(rows[0].size()));
      rows.push_back(row);
    }
    if (static_cast<int64_t>(rows.size()) != steps)
      return Status::DataLoss(file + ": " + std::to_string(rows.size()) + " rows, dataset.d says numbertimes=" +
                               std::to_string(steps));
    Eigen::MatrixXd seq(rows[0].size(), steps);
    for (int t = 0; t < steps; ++t)
      for (size_t i = 0; i < rows[t].size(); ++i) seq(i, t) = rows[t][i];
    if (!data.sequences.empty() && seq.rows() != data.sequences[0].rows())
      return Status::DataLoss(file + ": " + std::to_string(seq.rows()) + " DOFs, primitive_0_0.csv has " +
                               std::to_string(data.sequences[0].rows()));
    data.sequences.push_back(std::move(seq));
  }
  if (Status st = ReadNames(dir, &data); !st.ok()) return st;
  return data;
}

Status WriteNrlDataset(const Dataset& data, const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Status::IOError(dir + ": cannot create folder: " + ec.message());
  {
    const std::string meta = (fs::path(dir) / "dataset.d").string();
    std::ofstream out(meta);
    out << "samplingperiod=" << data.sampling_period_ms << "\nnumbertimes=" << data.steps()
        << "\nnumberprims=" << data.size() << "\n";
    if (!out) return Status::IOError(meta + ": write failed");
  }
  for (int p = 0; p < data.size(); ++p) {
    const std::string file = (fs::path(dir) / ("primitive_" + std::to_string(p) + "_0.csv")).string();
    std::ofstream out(file);
    out.precision(17);
    const auto& s = data.sequences[p];
    for (int t = 0; t < s.cols(); ++t) {
      for (int i = 0; i < s.rows(); ++i) out << (i ? "," : "") << s(i, t);
      out << "\n";
    }
    if (!out) return Status::IOError(file + ": write failed");
  }
  const std::string names = (fs::path(dir) / "names.txt").string();
  if (data.names.empty()) {
    fs::remove(names, ec);  // an earlier data set's names do not describe this one
    return Status::OK();
  }
  std::ofstream out(names);
  for (const std::string& n : data.names) out << n << "\n";
  if (!out) return Status::IOError(names + ": write failed");
  return Status::OK();
}

Dataset RepeatSequences(const Dataset& data, int loops) {
  Dataset out = data;
  for (Eigen::MatrixXd& s : out.sequences) s = s.replicate(1, loops).eval();
  return out;
}

}  // namespace dyad::pvrnn
