#include "introspection_commands.hpp"

#include <iomanip>
#include <map>
#include <memory>
#include <iostream>
#include <sstream>

#include <dyad/cdr_decoder.hpp>
#include <dyad/introspect.hpp>

namespace dyad::cli {
namespace {

// Prints samples as JSON, decoded with each type's own IDL text (parsed once per type); as hex
// with the reason when that fails.
SamplePrinter JsonPrinter() {
  auto schemas = std::make_shared<std::map<std::string, std::pair<cdr::Schema, std::string>>>();
  return [schemas](const TypeInfo& type, const uint8_t* data, size_t size) {
    auto it = schemas->find(type.name);
    if (it == schemas->end()) {
      std::string error;
      cdr::Schema schema = cdr::Schema::Parse(type.idl, &error);
      it = schemas->emplace(type.name, std::make_pair(std::move(schema), error)).first;
    }
    std::string error = it->second.second;
    std::vector<cdr::Field> fields;
    if (error.empty() && cdr::Decode(it->second.first, type.name, data, size, &fields, &error)) return cdr::ToJson(fields);
    std::ostringstream os;
    os << type.short_name() << " (" << error << ") " << size << " bytes:";
    for (size_t i = 0; i < size; ++i) os << (i % 4 == 0 ? " " : "") << std::hex << std::setw(2) << std::setfill('0') << int(data[i]);
    return os.str();
  };
}

}  // namespace

void AddIntrospectionCommands(CLI::App& app, int& exit_code) {
  static IntrospectOptions opts;
  static std::string topic;
  static uint64_t count = 0;
  static double duration = 0;
  static std::vector<std::string> plugins;

  auto add_common = [](CLI::App* c) {
    c->add_option("--domain", opts.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
    c->add_option("--wait", opts.wait_s, "Seconds of discovery before answering")->check(CLI::NonNegativeNumber);
  };

  auto* topics = app.add_subcommand("topics", "List the topics on the DDS domain with their types and endpoints");
  add_common(topics);
  topics->callback([&exit_code] { exit_code = ListTopics(opts, std::cout); });

  auto* echo = app.add_subcommand("echo", "Print the samples published on a topic");
  add_common(echo);
  echo->add_option("topic", topic, "Topic name")->required();
  echo->add_option("-n,--count", count, "Stop after this many samples (0: until Ctrl-C)");
  echo->add_option("--duration", duration, "Stop after this many seconds");
  echo->add_option("--plugins", plugins, "Plugin file or folder whose message types to know (repeatable)");
  echo->callback([&exit_code] {
    Catalog catalog;
    catalog.LoadDefault(plugins);
    exit_code = EchoTopic(opts, catalog, topic, count, duration, JsonPrinter(), std::cout, std::cerr);
  });

  auto* hz = app.add_subcommand("hz", "Measure the publication rate of a topic");
  add_common(hz);
  hz->add_option("topic", topic, "Topic name")->required();
  hz->add_option("--duration", duration, "Stop after this many seconds (0: until Ctrl-C)");
  hz->add_option("--plugins", plugins, "Plugin file or folder whose message types to know (repeatable)");
  hz->callback([&exit_code] {
    Catalog catalog;
    catalog.LoadDefault(plugins);
    exit_code = TopicHz(opts, catalog, topic, duration, std::cout, std::cerr);
  });
}

}  // namespace dyad::cli
