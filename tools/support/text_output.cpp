#include "text_output.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

namespace dyad::tools {

std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string MarkdownCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += "\\|";
    else out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out;
}

std::string CsvNumber(double v) {
  if (std::isnan(v)) return "";
  char text[32];  // the longest shortest double, "-2.2250738585072014e-308", is 24 characters
  const auto r = std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}

Status WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) return Status::IOError(path, "cannot write");
  return Status::OK();
}

}  // namespace dyad::tools
