#include "run_process.hpp"

#include <errno.h>

#include <filesystem>


namespace dyad::tools {

ExitStatus RunProcess(const std::vector<std::string>& args, const std::string& log) {
  ChildOptions o;
  o.log = log;
  return RunChild(args, o);
}

std::string ThisExecutable() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.string();
}

std::string DyadScriptPath(const std::string& name) {
  const std::filesystem::path exe = ThisExecutable();
  if (exe.empty()) return "/nonexistent/share/dyad/" + name;  // never a script of the working folder
  return (exe.parent_path().parent_path() / "share" / "dyad" / name).string();
}

ExitStatus RunDyadScript(const std::string& name, const std::vector<std::string>& args) {
  const std::string script = DyadScriptPath(name);
  if (!std::filesystem::exists(script)) return ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, ENOENT);
  // Debian's interpreter first: python3-matplotlib is installed for it, whatever else is on PATH.
  std::vector<std::string> all = {std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3", script};
  all.insert(all.end(), args.begin(), args.end());
  return RunProcess(all);
}

std::string ShellQuoted(const std::vector<std::string>& args) {
  std::string line;
  for (const std::string& a : args) {
    if (!line.empty()) line += ' ';
    const bool plain = !a.empty() && a.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                                         "0123456789_./=:,+@%-") == std::string::npos;
    if (plain) {
      line += a;
      continue;
    }
    line += '\'';
    for (char c : a) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += '\'';
  }
  return line;
}

}  // namespace dyad::tools
