// The type registry of a DdsParticipant: each graph topic carries one type, registered with Fast
// DDS as TypeInfo::dds_name() ("name#hash") and its topic created on the current generation (a
// renewal's new generation gets them all again: MakeGeneration). A second endpoint of a topic must
// bring the same type and DDS topic name, or is refused naming both. A topic new here has the
// endpoints discovered on it before checked against its type (DiscoveryListener::CheckDiscovered).
// The maps are guarded by the participant's mutex_ (discovery reads them on Fast DDS threads).
#include "dds/dds_internal.hpp"

#include <dyad/ros2_names.hpp>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

namespace dyad {

Status DdsParticipant::AddTopic(Generation& g, const std::string& topic, const std::string& dds_topic, const TypeInfo& type) {
  const std::string dds_type = type.dds_name();
  if (g.participant->find_type(dds_type).empty()) {
    fdds::TypeSupport support(type.make_type_support());
    if (support.register_type(g.participant, dds_type) != ReturnCode_t::RETCODE_OK)
      return Status::Internal("cannot register type " + dds_type);
  }
  fdds::Topic* t = g.participant->create_topic(dds_topic, dds_type, fdds::TOPIC_QOS_DEFAULT);
  if (t == nullptr) return Status::Internal("cannot create topic '" + dds_topic + "' of type " + dds_type);
  g.topics[topic] = t;
  return Status::OK();
}

Status DdsParticipant::GetTopic(const std::string& topic, const TypeInfo& type, const std::string& given_ros2_name) {
  std::string added;  // the DDS topic, when this call made it
  Status s = AddTopicOnce(topic, type, given_ros2_name, &added);
  // Outside mutex_: the check takes it. Endpoints of the topic discovered before it existed here.
  if (s.ok() && !added.empty()) listener_->CheckDiscovered(added);
  return s;
}

Status DdsParticipant::AddTopicOnce(const std::string& topic, const TypeInfo& type, const std::string& given_ros2_name,
                                    std::string* added) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string dds_type = type.dds_name();
  // A name starting with '/' is a ROS 2 topic's own (a watcher's `dyad echo /arm/pose`); graph
  // topics never start with '/' (validation).
  const std::string ros2_name = given_ros2_name.empty() && !topic.empty() && topic[0] == '/' ? topic : given_ros2_name;
  const std::string dds_topic = ros2_name.empty() ? topic : Ros2DdsTopic(ros2_name);
  if (auto it = topic_types_.find(topic); it != topic_types_.end()) {
    if (it->second != dds_type)
      return Status::InvalidArgument("topic '" + topic + "' already carries " + it->second + ", not " + dds_type);
    auto dds = dds_topics_.find(topic);
    if ((dds == dds_topics_.end() ? topic : dds->second) != dds_topic)
      return Status::InvalidArgument("topic '" + topic + "' is already DDS topic '" +
                                     (dds == dds_topics_.end() ? topic : dds->second) + "', not '" + dds_topic + "'");
    return Status::OK();
  }
  if (Status s = AddTopic(gen_, topic, dds_topic, type); !s.ok()) return s;
  topic_types_[topic] = dds_type;
  topic_infos_[topic] = &type;
  if (!ros2_name.empty()) {
    dds_topics_[topic] = dds_topic;
    ros2_topics_[dds_topic] = topic;
  }
  *added = dds_topic;
  return Status::OK();
}

}  // namespace dyad
