// How a visitor of running graphs joins them: the watchers (introspect.cpp: `dyad topics/echo/
// hz/status`) and the guests (guest.cpp: `dyad record`, `dyad bag play`). See dyad/introspect.hpp
// for what joining as a watcher means (UDP only, the graph's partitions, never waited for).
#pragma once

#include <iosfwd>
#include <memory>
#include <string>

#include <dyad/catalog.hpp>
#include <dyad/interrupt.hpp>
#include <dyad/introspect.hpp>

#include "dds/dds_participant.hpp"

namespace dyad {

// A watcher participant named `name` in the partitions of `o` (every run of its graph, one run,
// or every dyad run); null after saying why on `err`.
std::unique_ptr<DdsParticipant> JoinAsWatcher(const IntrospectOptions& o, const std::string& name, std::ostream& err);

// Waits until some writer of `topic` is discovered; returns its DDS type name or "".
std::string DiscoverType(DdsParticipant& p, const std::string& topic, double wait_s, const InterruptWatcher& interrupt);

// The catalog's type of a discovered DDS type name ("name#hash"); null after saying on `err` why
// not (another definition of the same IDL name, or a type no loaded plugin defines).
const TypeInfo* ResolveType(const Catalog& catalog, const std::string& dds_type, const std::string& topic, std::ostream& err);

}  // namespace dyad
