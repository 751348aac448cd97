// Why a process or a watcher of a local graph finds nobody (internal to the runtime).
//
// A graph that names no other machine has `network.scope: local` (graph.hpp, NetScope): its
// participants reach this machine only (loopback, shared memory). That default is kept; but a
// process started with `--process` on another machine, or a watcher there, then waits in vain,
// and "'mind' (not seen)" alone does not say why. Where nobody is found (the start barrier's
// timeout, a watcher that discovers nothing), LocalScopeNote is added to the message.
#pragma once

#include <string>

#include "dyad/graph.hpp"

namespace dyad {

// For a local scope, a clause to append after "; ": for a process (watcher false) "the graph is
// local (...): ... a process on another machine is never seen; to run it on several machines, set
// `network.scope: lan` ... or name the hosts (...)"; for a watcher, that it reaches this machine
// only and how to watch a graph of scope lan (its --graph). For scope lan: "" (nothing to add:
// the network is as the graph says).
std::string LocalScopeNote(const NetworkConfig& network, bool watcher = false);

}  // namespace dyad
