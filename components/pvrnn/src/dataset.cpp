#include "dyad/pvrnn/dataset.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "dyad/pvrnn/nrl_import.hpp"
#include "nrl_text.hpp"

namespace dyad::pvrnn {
namespace fs = std::filesystem;

namespace {

// names.txt, when there is one (dataset.hpp: its rules): one name per primitive, given to each of
// its sequences (a later sample's with " (sample s)").
Status ReadNames(const std::string& dir, const std::string& count_rule, Dataset* data) {
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
  if (static_cast<int>(names.size()) != data->primitives())
    return Status::DataLoss(file + ": " + std::to_string(names.size()) + " names, " + count_rule);
  data->names.clear();
  for (int k = 0; k < data->size(); ++k) {
    const int s = data->SampleOf(k);
    data->names.push_back(names[data->PrimitiveOf(k)] + (s > 0 ? " (sample " + std::to_string(s) + ")" : ""));
  }
  return Status::OK();
}

// dataset.d's counts; a key left out stays -1.
Status ReadMeta(const std::string& meta, Dataset* data, int64_t* steps, int64_t* prims) {
  auto kv = ReadKeyValueFile(meta);
  if (!kv.ok()) return kv.status();
  for (const auto& entry : kv.value()) {
    const std::string& k = entry.first;  // not a structured binding: clang 14 cannot capture one
    const std::string& v = entry.second;
    auto bad = [&](const char* rule) { return Status::DataLoss(meta + ": " + k + " = '" + v + "': " + rule); };
    std::vector<double> period;
    if (k == "samplingperiod" && !(internal::ParseNumberList(v, &period) && period.size() == 1 && period[0] > 0))
      return bad("must be a number > 0");
    if (k == "samplingperiod") data->sampling_period_ms = period[0];
    if (k == "numbertimes" && !internal::ParseInteger(v, 1, 10'000'000, steps))
      return bad("must be a whole number in 1..10000000");
    if (k == "numberprims" && !internal::ParseInteger(v, 1, 100'000, prims))
      return bad("must be a whole number in 1..100000");
  }
  if (*steps <= 0) return Status::DataLoss(meta + ": numbertimes missing");
  if (*prims <= 0) return Status::DataLoss(meta + ": numberprims missing");
  return Status::OK();
}

// "primitive_<p>_<s>.csv" as NRL writes the name (decimal, no leading zeros) -> {p, s}.
bool ParseSampleName(const std::string& name, std::pair<int, int>* ps) {
  const std::string head = "primitive_", tail = ".csv";
  if (name.size() <= head.size() + tail.size() || name.rfind(head, 0) != 0 || !name.ends_with(tail)) return false;
  const std::string mid = name.substr(head.size(), name.size() - head.size() - tail.size());
  const size_t u = mid.find('_');
  if (u == std::string::npos) return false;
  int64_t p = 0, s = 0;
  auto plain = [](const std::string& d) { return !d.empty() && d.size() < 10 && (d == "0" || d[0] != '0') && d.find_first_not_of("0123456789") == std::string::npos; };
  const std::string a = mid.substr(0, u), b = mid.substr(u + 1);
  if (!plain(a) || !plain(b) || !internal::ParseInteger(a, 0, 1'000'000'000, &p) || !internal::ParseInteger(b, 0, 1'000'000'000, &s))
    return false;
  *ps = {static_cast<int>(p), static_cast<int>(s)};
  return true;
}

// One sample file: DOFs x rows. `steps` > 0: it must have that many rows (`rule` says who says so).
StatusOr<Eigen::MatrixXd> ReadSampleFile(const std::string& file, int64_t steps, const std::string& rule) {
  std::ifstream in(file);
  if (!in) return Status::NotFound(file + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::vector<double> row;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (std::string bad; !internal::ParseNumberList(line, &row, &bad))
      return Status::DataLoss(file + ":" + std::to_string(line_no) + ": '" + bad +
                              "' is not a finite number (expected a comma-separated row of numbers)");
    if (!rows.empty() && row.size() != rows[0].size())
      return Status::DataLoss(file + ":" + std::to_string(line_no) + ": " + std::to_string(row.size()) +
                              " values, earlier rows have " + std::to_string(rows[0].size()));
    rows.push_back(row);
  }
  if (rows.empty()) return Status::DataLoss(file + ": no rows");
  if (steps > 0 && static_cast<int64_t>(rows.size()) != steps)
    return Status::DataLoss(file + ": " + std::to_string(rows.size()) + " rows, " + rule);
  Eigen::MatrixXd seq(rows[0].size(), rows.size());
  for (size_t t = 0; t < rows.size(); ++t)
    for (size_t i = 0; i < rows[t].size(); ++i) seq(i, t) = rows[t][i];
  return seq;
}

// The folder's files by name (hidden ones left out), and its samples by {primitive, sample}.
Status ListFolder(const std::string& dir, std::set<std::string>* files, std::map<std::pair<int, int>, std::string>* samples) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name[0] == '.' || !it->is_regular_file()) continue;
    files->insert(name);
    if (std::pair<int, int> ps; ParseSampleName(name, &ps)) (*samples)[ps] = name;
  }
  if (ec) return Status::NotFound(dir + ": cannot list the data set folder: " + ec.message());
  return Status::OK();
}

// Why a file of the folder was not read (`samples_of[p]`: how many samples of p were read).
std::string NotUsedReason(const std::string& name, const std::vector<int>& samples_of, bool has_meta) {
  std::pair<int, int> ps;
  if (!ParseSampleName(name, &ps))
    return "not a file of a data set (dataset.d, names.txt, primitive_<p>_<s>.csv)";
  const int prims = static_cast<int>(samples_of.size());
  if (ps.first >= prims)
    return has_meta ? "dataset.d says numberprims=" + std::to_string(prims)
                    : "primitive_" + std::to_string(prims) + "_0.csv is missing: primitives are read from 0 up to the first missing one";
  return "primitive_" + std::to_string(ps.first) + "_" + std::to_string(samples_of[ps.first]) +
         ".csv is missing: samples are read from 0 up to the first missing one";
}

}  // namespace

std::vector<int> Dataset::SequencesPerPrimitive() const {
  std::vector<int> n(primitives(), 0);
  for (int k = 0; k < size(); ++k) ++n[PrimitiveOf(k)];
  return n;
}

StatusOr<Dataset> LoadNrlDataset(const std::string& dir) {
  Dataset data;
  data.name = fs::path(dir).filename().string();
  if (data.name.empty()) data.name = fs::path(dir).parent_path().filename().string();
  const std::string meta = (fs::path(dir) / "dataset.d").string();
  const bool has_meta = fs::exists(meta);
  int64_t steps = -1, prims = -1;
  if (has_meta) {
    if (Status st = ReadMeta(meta, &data, &steps, &prims); !st.ok()) return st;
  }
  std::set<std::string> files;
  std::map<std::pair<int, int>, std::string> samples;
  if (Status st = ListFolder(dir, &files, &samples); !st.ok()) return st;
  if (!has_meta) {
    for (prims = 0; samples.count({static_cast<int>(prims), 0}); ++prims) {}
    if (prims == 0)
      return Status::NotFound(dir + ": neither dataset.d nor primitive_0_0.csv: not a data set (dataset.d optional, "
                              "primitive_<p>_<s>.csv from primitive_0_0.csv)");
  }
  std::string first_file;
  std::vector<int> samples_of(prims, 0);
  for (int p = 0; p < prims; ++p) {
    for (int s = 0; s == 0 || samples.count({p, s}); ++s) {
      const std::string name = "primitive_" + std::to_string(p) + "_" + std::to_string(s) + ".csv";
      const std::string file = (fs::path(dir) / name).string();
      if (!samples.count({p, s}))
        return Status::NotFound(file + ": cannot open (dataset.d lists " + std::to_string(prims) + " primitives)");
      const std::string rule = has_meta ? "dataset.d says numbertimes=" + std::to_string(steps)
                                        : first_file + " has " + std::to_string(steps);
      auto seq = ReadSampleFile(file, steps, rule);
      if (!seq.ok()) return seq.status();
      if (first_file.empty()) {
        first_file = name;
        steps = seq->cols();
      } else if (seq->rows() != data.sequences[0].rows()) {
        return Status::DataLoss(file + ": " + std::to_string(seq->rows()) + " DOFs, " + first_file + " has " +
                                std::to_string(data.sequences[0].rows()));
      }
      data.sequences.push_back(std::move(seq.value()));
      data.primitive.push_back(p);
      data.sample.push_back(s);
      ++samples_of[p];
      files.erase(name);
    }
  }
  files.erase("dataset.d");
  files.erase("names.txt");
  for (const std::string& f : files)
    data.warnings.push_back((fs::path(dir) / f).string() + ": not used (" + NotUsedReason(f, samples_of, has_meta) + ")");
  const std::string count_rule = has_meta ? "dataset.d says numberprims=" + std::to_string(prims)
                                          : "the data set has " + std::to_string(prims) + " primitives";
  if (Status st = ReadNames(dir, count_rule, &data); !st.ok()) return st;
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
        << "\nnumberprims=" << data.primitives() << "\n";
    if (!out) return Status::IOError(meta + ": write failed");
  }
  std::set<std::string> stale;
  std::map<std::pair<int, int>, std::string> old_samples;
  if (Status st = ListFolder(dir, &stale, &old_samples); !st.ok()) return st;
  for (int k = 0; k < data.size(); ++k) {
    const std::string name = "primitive_" + std::to_string(data.PrimitiveOf(k)) + "_" + std::to_string(data.SampleOf(k)) + ".csv";
    const std::string file = (fs::path(dir) / name).string();
    old_samples.erase({data.PrimitiveOf(k), data.SampleOf(k)});
    std::ofstream out(file);
    out.precision(17);
    const auto& s = data.sequences[k];
    for (int t = 0; t < s.cols(); ++t) {
      for (int i = 0; i < s.rows(); ++i) out << (i ? "," : "") << s(i, t);
      out << "\n";
    }
    if (!out) return Status::IOError(file + ": write failed");
  }
  for (const auto& entry : old_samples) fs::remove(fs::path(dir) / entry.second, ec);  // an earlier set's
  const std::string names = (fs::path(dir) / "names.txt").string();
  if (data.names.empty()) {
    fs::remove(names, ec);  // an earlier data set's names do not describe this one
    return Status::OK();
  }
  std::ofstream out(names);
  for (int k = 0; k < data.size(); ++k)
    if (data.SampleOf(k) == 0) out << data.names[k] << "\n";
  if (!out) return Status::IOError(names + ": write failed");
  return Status::OK();
}

Dataset RepeatSequences(const Dataset& data, int loops) {
  Dataset out = data;
  for (Eigen::MatrixXd& s : out.sequences) s = s.replicate(1, loops).eval();
  return out;
}

}  // namespace dyad::pvrnn
