// Markdown reference tables from Describe() and from the IDL text of message types.
#include "reference_markdown.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <regex>
#include <sstream>
#include <vector>

#include "text_output.hpp"

namespace dyad::cli {
namespace {

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// The anchor a Markdown renderer gives the heading "## Name" of a message type: lower case.
std::string Anchor(const std::string& name) {
  std::string anchor;
  for (char c : name) anchor += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return anchor;
}

struct Member {
  std::string name, type, doc;
};

struct StructText {
  std::string doc;
  std::vector<Member> members;
  bool found = false;
};

// The definition of struct `name` in `idl` (the text dyad_generate_type_traits stores): the `//`
// comment block right above it (blank and `module` lines between are skipped) and one Member per
// member line ("double x, y;  // text" gives name "x, y").
StructText FindStruct(const std::string& idl, const std::string& name) {
  std::vector<std::string> lines;
  std::istringstream in(idl);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const std::regex open("^\\s*struct\\s+" + name + "\\b.*");
  const std::regex member("^(.*\\S)\\s+([A-Za-z_]\\w*(\\s*\\[[^\\]]*\\])*(\\s*,\\s*[A-Za-z_]\\w*(\\s*\\[[^\\]]*\\])*)*)$");
  StructText out;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (!std::regex_match(lines[i], open)) continue;
    out.found = true;
    std::vector<std::string> doc;
    for (size_t k = i; k-- > 0;) {
      const std::string t = Trim(lines[k]);
      if (t.empty() || t.rfind("module ", 0) == 0) {
        if (!doc.empty()) break;
        continue;
      }
      if (t.rfind("//", 0) != 0) break;
      doc.insert(doc.begin(), Trim(t.substr(2)));
    }
    for (const auto& d : doc) out.doc += (out.doc.empty() ? "" : " ") + d;
    for (size_t k = i + (lines[i].find('{') == std::string::npos ? 2 : 1); k < lines.size(); ++k) {
      std::string text = lines[k], comment;
      if (const auto c = text.find("//"); c != std::string::npos) {
        comment = Trim(text.substr(c + 2));
        text = text.substr(0, c);
      }
      text = Trim(text);
      if (text.rfind("}", 0) == 0) break;
      if (text.empty()) continue;
      if (!text.empty() && text.back() == ';') text = Trim(text.substr(0, text.size() - 1));
      std::smatch m;
      if (std::regex_match(text, m, member)) out.members.push_back({m[2].str(), m[1].str(), comment});
      else out.members.push_back({text, "", comment});
    }
    break;
  }
  return out;
}

}  // namespace

std::string ParamRangeText(const ParamSpec& p) {
  auto bound = [&](std::optional<double> v, const char* none) -> std::string {
    if (!v) return none;
    if (p.type == ParamType::kInt && std::abs(*v) < 9.2e18) return std::to_string(static_cast<int64_t>(*v));
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, *v);
    return std::string(buf, r.ptr);
  };
  return bound(p.min, "-inf") + ".." + bound(p.max, "inf");
}

std::string ComponentReferenceMarkdown(const std::string& name, const CatalogEntry& entry) {
  const ComponentSpec& spec = entry.spec;
  std::ostringstream out;
  out << "<!-- BEGIN dyad types --markdown " << name
      << " (generated from its Describe(): change the code, then run python3 tools/docs.py) -->\n";
  if (!spec.summary().empty()) out << spec.summary() << "\n\n";
  if (!spec.inputs().empty() || !spec.outputs().empty()) {
    out << "| port | message | |\n| --- | --- | --- |\n";
    for (const auto& p : spec.inputs())
      out << "| input `" << p.name << "`" << (p.optional ? " (optional)" : "") << " | " << p.type->short_name() << " | "
          << tools::MarkdownCell(p.doc) << " |\n";
    for (const auto& p : spec.outputs())
      out << "| output `" << p.name << "` | " << p.type->short_name() << " | " << tools::MarkdownCell(p.doc) << " |\n";
    out << "\n";
  }
  if (!spec.params().empty()) {
    out << "| param | type | default | |\n| --- | --- | --- | --- |\n";
    for (const auto& p : spec.params()) {
      std::string type = ToString(p.type);
      if (p.path) type += " (path)";
      if (p.live) type += " (live)";
      if (p.min || p.max) type += ", " + ParamRangeText(p);
      if (!p.unit.empty()) type += " [" + p.unit + "]";
      if (!p.choices.empty()) {
        type += ", one of";
        for (size_t i = 0; i < p.choices.size(); ++i) {
          type += i ? ", `" : " `";
          type += p.choices[i];
          type += '`';
        }
      }
      out << "| `" << p.name << "` | " << tools::MarkdownCell(type) << " | ";
      // A kYaml default is YAML text already: shown as written, not as a quoted string.
      const auto* yaml = p.type == ParamType::kYaml && p.default_value ? std::get_if<std::string>(&*p.default_value) : nullptr;
      if (yaml) out << '`' << tools::MarkdownCell(*yaml) << '`';
      else if (p.default_value) out << '`' << tools::MarkdownCell(ToYamlText(*p.default_value)) << '`';
      else out << "required";
      out << " | " << tools::MarkdownCell(p.doc) << " |\n";
    }
  }
  out << "<!-- END dyad types --markdown " << name << " -->\n";
  return out.str();
}

std::string MessageReferenceMarkdown(const Catalog& catalog) {
  std::ostringstream out;
  out << "<!-- Generated by `dyad types --messages --markdown` from the IDL of idl/ (python3 tools/docs.py):\n"
         "     edit the .idl files, not this file. -->\n"
         "# Message types\n\n"
         "Every sample starts with a `Header` (source component, sequence number, stamp). Types are\n"
         "OMG IDL (`idl/*.idl`), compiled by fastddsgen at build time; on the wire a type is named\n"
         "`<IDL name>#<hash of its definition>` (docs/runtime.md). Graphs name them by their short name\n"
         "(`topics: {robot/state: {type: CartesianState}}`).\n\n"
         "ROS 2 message types (`idl/ros2/`, docs/ros2.md) follow dyad's: named as ROS 2 names them\n"
         "(`geometry_msgs/msg/TwistStamped`), on the wire as ROS 2's middlewares do\n"
         "(`geometry_msgs::msg::dds_::TwistStamped_`, no hash), with no dyad `Header`.\n\n";
  // dyad's own types first, then the ROS 2 ones.
  std::vector<const TypeInfo*> types;
  for (bool ros2 : {false, true})
    for (const TypeInfo* t : catalog.MessageTypes())
      if (t->ros2() == ros2) types.push_back(t);
  for (const TypeInfo* t : types) out << "- [" << t->short_name() << "](#" << Anchor(t->short_name()) << ")\n";
  for (const TypeInfo* t : types) {
    const StructText s = FindStruct(t->idl, t->name.substr(t->name.rfind("::") + 2));
    out << "\n## " << t->short_name() << "\n\n`" << t->name << "`";
    if (!s.doc.empty()) out << ": " << s.doc;
    out << "\n\n";
    if (!s.found) {
      out << "(its IDL text does not define it)\n";
      continue;
    }
    out << "| field | IDL type | |\n| --- | --- | --- |\n";
    for (const Member& m : s.members)
      out << "| `" << tools::MarkdownCell(m.name) << "` | `" << tools::MarkdownCell(m.type) << "` | " << tools::MarkdownCell(m.doc) << " |\n";
  }
  return out.str();
}

}  // namespace dyad::cli
