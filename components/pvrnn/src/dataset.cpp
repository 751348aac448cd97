#include "dyad/pvrnn/dataset.hpp"

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dyad/pvrnn/nrl_import.hpp"

namespace dyad::pvrnn {
namespace fs = std::filesystem;

namespace {

// Parses comma-separated doubles; false on any malformed field.
bool ParseRow(const std::string& line, std::vector<double>* out) {
  out->clear();
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) {
    size_t b = field.find_first_not_of(" \t\r"), e = field.find_last_not_of(" \t\r");
    if (b == std::string::npos) return false;
    const char* first = field.data() + b;
    const char* last = field.data() + e + 1;
    double v = 0;
    auto res = std::from_chars(first, last, v);
    if (res.ec != std::errc() || res.ptr != last) return false;
    out->push_back(v);
  }
  return !out->empty();
}

}  // namespace

StatusOr<Dataset> LoadNrlDataset(const std::string& dir) {
  const std::string meta = (fs::path(dir) / "dataset.d").string();
  auto kv = ReadKeyValueFile(meta);
  if (!kv.ok()) return kv.status();
  Dataset data;
  data.name = fs::path(dir).filename().string();
  if (data.name.empty()) data.name = fs::path(dir).parent_path().filename().string();
  int steps = -1, prims = -1;
  for (const auto& [k, v] : kv.value()) {
    try {
      if (k == "samplingperiod") data.sampling_period_ms = std::stod(v);
      if (k == "numbertimes") steps = std::stoi(v);
      if (k == "numberprims") prims = std::stoi(v);
    } catch (const std::exception&) {
      return Status::DataLoss(meta + ": " + k + " = '" + v + "': not a number");
    }
  }
  if (steps <= 0) return Status::DataLoss(meta + ": numbertimes missing or not > 0");
  if (prims <= 0) return Status::DataLoss(meta + ": numberprims missing or not > 0");
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
      if (!ParseRow(line, &row))
        return Status::DataLoss(file + ":" + std::to_string(line_no) + ": not a comma-separated row of numbers");
      if (!rows.empty() && row.size() != rows[0].size())
        return Status::DataLoss(file + ":" + std::to_string(line_no) + ": " + std::to_string(row.size()) +
                                 " values, earlier rows have " + std::to_string(rows[0].size()));
      rows.push_back(row);
    }
    if (static_cast<int>(rows.size()) != steps)
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
  return Status::OK();
}

}  // namespace dyad::pvrnn
