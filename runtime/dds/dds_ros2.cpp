// ROS 2 topics' endpoints (TopicQos::ros2_name, docs/ros2.md): such a topic is DDS topic
// "rt/..." (Ros2DdsTopic, named in AddTopicOnce), and its readers and writers go on each
// generation's second subscriber and publisher, which are in the default partition, where ROS 2
// peers are, not in the run's partition. Discovery speaks of them by the graph's name again
// (TopicOfDds).
#include "dds/dds_internal.hpp"

#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

namespace dyad {

std::string DdsParticipant::TopicOfDds(const std::string& dds_topic) const {
  auto it = ros2_topics_.find(dds_topic);
  return it == ros2_topics_.end() ? dds_topic : it->second;
}

// Not under mutex_: creating an endpoint calls the discovery listener back, which takes it.
// (Generations are swapped and deleted on the executor's thread, which is the one calling.)
fdds::DataReader* DdsParticipant::NewReader(const std::string& topic, const fdds::DataReaderQos& qos) {
  fdds::Subscriber* sub = nullptr;
  fdds::Topic* t = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sub = dds_topics_.count(topic) ? gen_.ros2_subscriber : gen_.subscriber;
    t = gen_.topics.at(topic);
  }
  return sub->create_datareader(t, qos, nullptr, fdds::StatusMask::none());
}

fdds::DataWriter* DdsParticipant::NewWriter(const std::string& topic, const fdds::DataWriterQos& qos) {
  fdds::Publisher* pub = nullptr;
  fdds::Topic* t = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pub = dds_topics_.count(topic) ? gen_.ros2_publisher : gen_.publisher;
    t = gen_.topics.at(topic);
  }
  return pub->create_datawriter(t, qos);
}

}  // namespace dyad
