// The names a participant keeps of its peers (DdsParticipant::KnownPeerNames, dds_discovery.cpp):
// one per peer present, forgotten when the peer leaves, so that peers coming and going for hours
// (restarts, watchers, a stranger knocking with a new GUID each time) do not grow them.
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "dds/dds_participant.hpp"
#include "dyad/testing/dds_domain.hpp"

namespace dyad {
namespace {

std::unique_ptr<DdsParticipant> Participant(const std::string& name) {
  DdsParticipant::Options o;
  o.scope = DdsParticipant::Scope::kProcessOnly;  // its peers are in this process; no one else's
  auto p = DdsParticipant::Create(testing::DomainForThisProcess(), name, std::move(o));
  EXPECT_TRUE(p.ok()) << p.status().message();
  return p.ok() ? std::move(p.value()) : nullptr;
}

// Waits (10 s at most) until `p` keeps `n` peers' names; false if it never does.
bool AwaitPeerNames(const DdsParticipant& p, size_t n) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (p.KnownPeerNames() != n && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return p.KnownPeerNames() == n;
}

TEST(PeerNames, StayAsManyAsThePeersPresentAcrossJoinsAndLeaves) {
  auto watcher = Participant("dyad/peer_names/watcher");
  auto steady = Participant("dyad/peer_names/steady");
  ASSERT_TRUE(watcher && steady);
  ASSERT_TRUE(AwaitPeerNames(*watcher, 1)) << watcher->KnownPeerNames();
  for (int i = 0; i < 20; ++i) {
    auto visitor = Participant("dyad/peer_names/visitor_" + std::to_string(i));
    ASSERT_TRUE(visitor);
    ASSERT_TRUE(AwaitPeerNames(*watcher, 2)) << "visitor " << i << " joined: " << watcher->KnownPeerNames();
    visitor.reset();  // leaves: Fast DDS reports it REMOVED
    ASSERT_TRUE(AwaitPeerNames(*watcher, 1)) << "visitor " << i << " left, still kept: " << watcher->KnownPeerNames();
  }
  steady.reset();
  EXPECT_TRUE(AwaitPeerNames(*watcher, 0)) << watcher->KnownPeerNames();
}

}  // namespace
}  // namespace dyad
