#include "hosts/run_arguments.hpp"

#include <cstdio>

namespace dyad {
namespace {

std::string ExactText(double value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", value);  // to_string would round 1e-7 to 0
  return text;
}

}  // namespace

std::vector<std::string> RunArguments(const RunOptions& options) {
  const RunOptions defaults;
  std::vector<std::string> args = {"run", options.graph_path};
  auto add = [&args](const char* flag, std::string value) { args.insert(args.end(), {flag, std::move(value)}); };
  if (options.process != defaults.process) add("--process", options.process);
  if (options.restart_count != defaults.restart_count) add("--restart-count", std::to_string(options.restart_count));
  for (const auto& o : options.overrides) add("--set", o.text);
  for (const auto& p : options.plugin_paths) add("--plugins", p);
  if (options.duration_s != defaults.duration_s) add("--duration", ExactText(options.duration_s));
  if (options.stats_period_s != defaults.stats_period_s) add("--stats-period", ExactText(options.stats_period_s));
  if (options.steps != defaults.steps) add("--steps", std::to_string(options.steps));
  if (options.quiet) args.push_back("--quiet");
  if (options.strict) args.push_back("--strict");
  if (options.run_id != defaults.run_id) add("--run-id", options.run_id);
  if (options.host != defaults.host) add("--host", options.host);
  if (options.logs_dir != defaults.logs_dir) add("--logs", options.logs_dir);
  return args;
}

}  // namespace dyad
