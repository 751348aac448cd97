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
// starts with `Header header;`), which Output<T>::Publish stamps.
//
// The traits only declare MakeTypeSupport: its definition (DYAD_MESSAGE_TYPE_SUPPORT) needs
// fastddsgen's PubSubTypes headers, and with them most of Fast DDS, so it lives in the generated
// types_support.cpp of the messages' library, and the headers in types_support.hpp for code that
// instantiates a PubSubType itself. A file that only uses messages does not parse Fast DDS.
//
// ROS 2 message types (idl/ros2/, docs/ros2.md) are the exception: named as ROS 2's middlewares
// name them on the wire ("geometry_msgs::msg::dds_::TwistStamped_", also known by their ROS 2
// name "geometry_msgs/msg/TwistStamped"), their DDS type name carries no hash (ROS 2 peers
// match on the plain name), and they have no dyad Header: the component fills their
// std_msgs/Header (stamp, frame_id) itself.
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
  std::string ros2_name;  // "geometry_msgs/msg/Twist" for a ROS 2 type; empty for dyad's own
  // Returns a new Fast DDS type support for T, already renamed to dds_name(). Caller owns it.
  std::function<eprosima::fastdds::dds::TopicDataType*()> make_type_support;

  bool ros2() const { return !ros2_name.empty(); }
  // The DDS type name: "<name>#<hash>", or the plain IDL name for a ROS 2 type.
  std::string dds_name() const { return ros2() ? name : name + "#" + hash; }
  // "HumanInput": the name after the last "::"; a ROS 2 type's ROS 2 name.
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
    i.ros2_name = MessageTraits<T>::kRos2Name;
    std::string dds_name = i.dds_name();
    i.make_type_support = [dds_name]() -> eprosima::fastdds::dds::TopicDataType* {
      return MessageTraits<T>::MakeTypeSupport(dds_name.c_str());
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
    static constexpr const char* kRos2Name = "";                 \
    static constexpr bool kDyadHeader = true;                    \
    static ::eprosima::fastdds::dds::TopicDataType* MakeTypeSupport(const char* dds_name); \
  }

// Declares MessageTraits for the ROS 2 type NS::NAME ("<pkg>::msg::dds_", "<Type>_"), known as
// ROS2_NAME ("<pkg>/msg/<Type>"): no dyad Header, a plain DDS type name.
#define DYAD_ROS2_MESSAGE_TYPE(NS, NAME, ROS2_NAME, HASH, IDL)    \
  template <>                                                    \
  struct dyad::MessageTraits<NS::NAME> {                         \
    using PubSubType = NS::NAME##PubSubType;                     \
    static constexpr const char* kName = #NS "::" #NAME;         \
    static constexpr const char* kHash = HASH;                   \
    static constexpr const char* kIdl = IDL;                     \
    static constexpr const char* kRos2Name = ROS2_NAME;          \
    static constexpr bool kDyadHeader = false;                   \
    static ::eprosima::fastdds::dds::TopicDataType* MakeTypeSupport(const char* dds_name); \
  }

// Defines MessageTraits<NS::NAME>::MakeTypeSupport (generated types_support.cpp, where NS::NAME's
// PubSubTypes header is included): a new type support named `dds_name`, owned by the caller.
#define DYAD_MESSAGE_TYPE_SUPPORT(NS, NAME)                                                              \
  ::eprosima::fastdds::dds::TopicDataType* dyad::MessageTraits<NS::NAME>::MakeTypeSupport(const char* dds_name) { \
    auto* t = new NS::NAME##PubSubType();                                                                \
    t->setName(dds_name);                                                                                \
    return t;                                                                                            \
  }
