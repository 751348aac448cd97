// dyad/introspect.hpp — looking at a running experiment from outside: `dyad topics`,
// `dyad echo`, `dyad hz`. Each joins the DDS domain as an ordinary participant.
//
// Types are resolved from the topic's discovered DDS type name ("name#hash") against the
// message types this dyad knows (built-in IDL and loaded plugins). A topic whose type has the
// same IDL name but another hash was built from another IDL version: reported, not read.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include <dyad/catalog.hpp>

namespace dyad {

struct IntrospectOptions {
  int domain_id = 0;
  double wait_s = 2.0;      // discovery time before answering / giving up on a topic
};

// Prints one line per topic: name, type, writers, readers, participants. Returns 0, or 1 when
// nothing was found.
int ListTopics(const IntrospectOptions& options, std::ostream& out);

// Turns one serialized sample (CDR with encapsulation) of `type` into text.
using SamplePrinter = std::function<std::string(const TypeInfo& type, const uint8_t* data, size_t size)>;

// Prints `count` samples (0: until SIGINT or `duration_s`), one per line.
int EchoTopic(const IntrospectOptions& options, const Catalog& catalog, const std::string& topic, uint64_t count,
              double duration_s, const SamplePrinter& printer, std::ostream& out, std::ostream& err);

// Prints the receive rate every second (rate, mean/min/max period, samples) for `duration_s`
// (0: until SIGINT); returns 1 if no sample arrived.
int TopicHz(const IntrospectOptions& options, const Catalog& catalog, const std::string& topic, double duration_s,
            std::ostream& out, std::ostream& err);

}  // namespace dyad
