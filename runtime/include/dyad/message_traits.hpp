// dyad/message_traits.hpp — what dyad knows about a message type.
//
// Every message type is an IDL struct compiled by fastddsgen. dyad::MessageTraits<T> is
// specialised for each one by the generated header dyad/msg/types.hpp (for third-party IDL, call
// the CMake function dyad_generate_type_traits, installed with dyad). It names:
//   - the IDL type name ("dyad::msg::HumanInput"),
//   - a hash of the IDL definition (16 hex digits),
//   - the IDL text (includes inlined): the schema a recording carries.
// On the wire the DDS type name is "<name>#<hash>": endpoints built from different definitions
// never match, and the runtime reports the mismatch (Fast DDS 2.9 would otherwise match same-name,
// different-layout types and drop every sample silently).
//
// A message type T must have a member `dyad::msg::Header& header()` (every dyad IDL struct
// starts with `Header header;`).
#pragma once

#include <functional>
#include <memory>
#include <string>

namespace eprosima::fastdds::dds { class TopicDataType; }

namespace dyad {

// The runtime's type-erased view of a message type.
struct TypeInfo {
  std::string name;  // IDL name, e.g. "dyad::msg::HumanInput"
  std::string hash;  // 16 hex digits of the definition's SHA-256
  std::string idl;   // IDL text, includes inlined
  // Returns a new Fast DDS type support for T, already renamed to dds_name(). Caller owns it.
  std::function<eprosima::fastdds::dds::TopicDataType*()> make_type_support;

  std::string dds_name() const { return name + "#" + hash; }
  // "HumanInput": the name after the last "::".
  std::string short_name() const;
};

// Specialised per message type (see the file comment). The primary template is undefined, so
// using a type without traits fails to compile naming the type.
template <class T>
struct MessageTraits;

// The TypeInfo of T, built once.
template <class T>
const TypeInfo& TypeInfoOf() {
  static const TypeInfo info = [] {
    TypeInfo i;
    i.name = MessageTraits<T>::kName;
    i.hash = MessageTraits<T>::kHash;
    i.idl = MessageTraits<T>::kIdl;
    std::string dds_name = i.dds_name();
    i.make_type_support = [dds_name]() -> eprosima::fastdds::dds::TopicDataType* {
      auto* t = new typename MessageTraits<T>::PubSubType();
      t->setName(dds_name.c_str());
      return t;
    };
    return i;
  }();
  return info;
}

}  // namespace dyad

// Declares MessageTraits for NS::NAME, whose fastddsgen type support is NS::NAME##PubSubType.
#define DYAD_MESSAGE_TYPE(NS, NAME, HASH, IDL)                   \
  template <>                                                    \
  struct dyad::MessageTraits<NS::NAME> {                         \
    using PubSubType = NS::NAME##PubSubType;                     \
    static constexpr const char* kName = #NS "::" #NAME;         \
    static constexpr const char* kHash = HASH;                   \
    static constexpr const char* kIdl = IDL;                     \
  }
