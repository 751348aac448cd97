// Test peer: publishes dyad::msg::Counter under a different definition hash, as a process built
// from another version of the IDL would. Usage: dyad_type_peer DOMAIN TOPIC SECONDS [PARTITION]
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <thread>

#include <dyad/msg/types.hpp>
#include <dyad/msg/types_support.hpp>

#include "dds/dds_participant.hpp"

int main(int argc, char** argv) {
  if (argc != 4 && argc != 5) {
    std::cerr << "usage: dyad_type_peer DOMAIN TOPIC SECONDS [PARTITION]\n";
    return 2;
  }
  dyad::TypeInfo other = dyad::TypeInfoOf<dyad::msg::Counter>();
  other.hash = "0000000000000000";
  const std::string dds_name = other.dds_name();
  other.make_type_support = [dds_name] {
    auto* t = new dyad::msg::CounterPubSubType();
    t->setName(dds_name.c_str());
    return static_cast<eprosima::fastdds::dds::TopicDataType*>(t);
  };
  dyad::DdsParticipant::Options po;
  if (argc == 5) po.partitions = {argv[4]};
  auto p = dyad::DdsParticipant::Create(std::atoi(argv[1]), "type-peer", std::move(po));
  if (!p.ok()) return 1;
  auto w = p.value()->CreateWriter(argv[2], other, dyad::TopicQos{});
  if (!w.ok()) return 1;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[3]));
  dyad::msg::Counter c;
  while (std::chrono::steady_clock::now() < end) {
    c.value(c.value() + 1);
    w.value()->Write(&c).IgnoreError();  // a bare peer: only its presence matters
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}
