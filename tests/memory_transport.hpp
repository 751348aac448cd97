// MemoryTransport — an in-memory Transport (runtime/dds/transport.hpp) for the executor's unit
// tests: no DDS, no threads of its own (endpoints may be made while other threads write: the
// ClockSync and StartBarrier tests do). A write is delivered synchronously, inside Write(), to
// every reader of the topic, as Fast DDS does within a process; samples travel as CDR made by
// the type's own TypeSupport. KEEP_LAST keeps `depth` samples per reader (the oldest dropped),
// KEEP_ALL keeps everything. Test code only.
//
// It records what happens to it in an event log shared with the test ("transport destroyed"),
// so tests can assert the order in which the executor tears things down.
#pragma once

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "dds/transport.hpp"

namespace dyad::testing {

class MemoryTransport final : public Transport {
 public:
  using Log = std::function<void(const std::string&)>;
  // `spurious`: readers are notified twice per sample, as Fast DDS sometimes does.
  explicit MemoryTransport(Log log = nullptr, bool spurious = false) : log_(std::move(log)), spurious_(spurious) {}
  ~MemoryTransport() override {
    for (auto& r : serialized_readers_) r->Close();
    if (log_) log_("transport destroyed");
  }

  StatusOr<TypedReader*> CreateReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                      std::function<void()> on_data) override {
    std::lock_guard<std::mutex> lock(topology_);  // endpoints may be made while others write
    if (Status s = CheckType(topic, type); !s.ok()) return s;
    readers_.push_back(std::make_unique<Reader>(type, qos, std::move(on_data), spurious_));
    topics_[topic].readers.push_back(readers_.back().get());
    return readers_.back().get();
  }
  StatusOr<TypedWriter*> CreateWriter(const std::string& topic, const TypeInfo& type, const TopicQos&) override {
    std::lock_guard<std::mutex> lock(topology_);  // endpoints may be made while others write
    if (Status s = CheckType(topic, type); !s.ok()) return s;
    writers_.push_back(std::make_unique<Writer>(this, topic, type));
    return writers_.back().get();
  }
  StatusOr<SerializedSubscription*> CreateSerializedReader(const std::string& topic, const TypeInfo& type, const TopicQos&,
                                                           const Clock* clock, SerializedCallback callback) override {
    std::lock_guard<std::mutex> lock(topology_);  // endpoints may be made while others write
    if (Status s = CheckType(topic, type); !s.ok()) return s;
    serialized_readers_.push_back(std::make_unique<SerializedReader>(topic, clock, std::move(callback), true));
    topics_[topic].serialized.push_back(serialized_readers_.back().get());
    return serialized_readers_.back().get();
  }
  // Stopped: samples are not kept (a KEEP_LAST history is not modelled).
  StatusOr<OnDemandReader*> CreateOnDemandReader(const std::string& topic, const TypeInfo& type, const TopicQos&,
                                                 const Clock* clock, SerializedCallback callback) override {
    std::lock_guard<std::mutex> lock(topology_);  // endpoints may be made while others write
    if (Status s = CheckType(topic, type); !s.ok()) return s;
    serialized_readers_.push_back(std::make_unique<SerializedReader>(topic, clock, std::move(callback), false));
    topics_[topic].serialized.push_back(serialized_readers_.back().get());
    return serialized_readers_.back().get();
  }
  StatusOr<SerializedWriter*> CreateSerializedWriter(const std::string& topic, const TypeInfo& type, const TopicQos&,
                                                     const Clock*) override {
    std::lock_guard<std::mutex> lock(topology_);  // endpoints may be made while others write
    if (Status s = CheckType(topic, type); !s.ok()) return s;
    serialized_writers_.push_back(std::make_unique<RawWriter>(this, topic, type));
    return serialized_writers_.back().get();
  }

 private:
  using Bytes = std::vector<uint8_t>;

  class Reader final : public TypedReader {
   public:
    Reader(const TypeInfo& type, const TopicQos& qos, std::function<void()> on_data, bool spurious)
        : support_(type.make_type_support()), qos_(qos), on_data_(std::move(on_data)), spurious_(spurious) {}
    ~Reader() override { delete support_; }
    bool TakeNext(void* sample) override {
      Bytes b;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (queue_.empty()) return false;
        b = std::move(queue_.front());
        queue_.pop_front();
      }
      eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<uint32_t>(b.size()));
      std::copy(b.begin(), b.end(), payload.data);
      payload.length = static_cast<uint32_t>(b.size());
      return support_->deserialize(&payload, sample);
    }
    uint64_t Unread() const override {
      std::lock_guard<std::mutex> lock(mutex_);
      return queue_.size();
    }
    void Deliver(const Bytes& b) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        queue_.push_back(b);
        if (!qos_.keep_all && queue_.size() > static_cast<size_t>(qos_.depth)) queue_.pop_front();
      }
      if (on_data_) on_data_();
      if (on_data_ && spurious_) on_data_();
    }

   private:
    eprosima::fastdds::dds::TopicDataType* support_;
    TopicQos qos_;
    std::function<void()> on_data_;
    bool spurious_;
    mutable std::mutex mutex_;
    std::deque<Bytes> queue_;
  };

  class SerializedReader final : public OnDemandReader {
   public:
    SerializedReader(std::string topic, const Clock* clock, SerializedCallback cb, bool started)
        : topic_(std::move(topic)), clock_(clock), cb_(std::move(cb)), started_(started) {}
    void Close() override {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    uint64_t delivered() const override { return delivered_; }
    const std::string& topic() const override { return topic_; }
    Status Start() override {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_) return Status::FailedPrecondition("topic '" + topic_ + "': subscription closed");
      started_ = true;
      return Status::OK();
    }
    void Stop() override {
      std::lock_guard<std::mutex> lock(mutex_);
      started_ = false;
    }
    bool started() const override {
      std::lock_guard<std::mutex> lock(mutex_);
      return started_;
    }
    void Deliver(const Bytes& b, int64_t stamp, uint64_t sequence) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_ || !started_) return;
      SerializedSample s;
      s.cdr = std::span<const uint8_t>(b.data(), b.size());
      s.source_stamp_ns = stamp;
      s.receive_ns = clock_->now_ns();
      s.sequence = sequence;
      cb_(s);
      ++delivered_;
    }

   private:
    std::string topic_;
    const Clock* clock_;
    SerializedCallback cb_;
    mutable std::mutex mutex_;
    bool closed_ = false;
    bool started_;
    uint64_t delivered_ = 0;
  };

  class Writer final : public TypedWriter {
   public:
    Writer(MemoryTransport* t, std::string topic, const TypeInfo& type)
        : t_(t), topic_(std::move(topic)), support_(type.make_type_support()) {}
    ~Writer() override { delete support_; }
    Status Write(const void* sample) override { return WriteStamped(sample, 0); }
    Status WriteStamped(const void* sample, int64_t stamp_ns) override {
      eprosima::fastrtps::rtps::SerializedPayload_t payload(support_->getSerializedSizeProvider(const_cast<void*>(sample))());
      if (!support_->serialize(const_cast<void*>(sample), &payload)) return Status::Internal(topic_ + ": cannot serialize");
      t_->Publish(topic_, Bytes(payload.data, payload.data + payload.length), stamp_ns, ++sequence_);
      return Status::OK();
    }
    int matched() const override {
      std::lock_guard<std::mutex> lock(t_->topology_);
      return static_cast<int>(t_->topics_[topic_].readers.size());
    }
    // Write() delivered to every reader before it returned: nothing is ever unacknowledged.
    bool AwaitAcknowledged(double /*timeout_s*/) override { return true; }

   private:
    MemoryTransport* t_;
    std::string topic_;
    eprosima::fastdds::dds::TopicDataType* support_;
    uint64_t sequence_ = 0;
  };

  class RawWriter final : public SerializedWriter {
   public:
    RawWriter(MemoryTransport* t, std::string topic, const TypeInfo& type) : t_(t), topic_(std::move(topic)), type_(type) {}
    const std::string& topic() const override { return topic_; }
    const TypeInfo& type() const override { return type_; }
    Status Write(std::span<const uint8_t> cdr, int64_t stamp) override {
      t_->Publish(topic_, Bytes(cdr.begin(), cdr.end()), stamp, ++written_);
      return Status::OK();
    }
    uint64_t written() const override { return written_; }

   private:
    MemoryTransport* t_;
    std::string topic_;
    const TypeInfo& type_;
    uint64_t written_ = 0;
  };

  struct Topic {
    std::string type;
    std::vector<Reader*> readers;
    std::vector<SerializedReader*> serialized;
  };

  Status CheckType(const std::string& topic, const TypeInfo& type) {
    Topic& t = topics_[topic];
    if (t.type.empty()) t.type = type.dds_name();
    if (t.type != type.dds_name()) return Status::InvalidArgument("topic '" + topic + "' already carries " + t.type);
    return Status::OK();
  }
  // Delivers outside the lock (a reader's callback may write, or make an endpoint); the readers
  // themselves live as long as the transport.
  void Publish(const std::string& topic, const Bytes& bytes, int64_t stamp, uint64_t sequence) {
    std::vector<Reader*> readers;
    std::vector<SerializedReader*> serialized;
    {
      std::lock_guard<std::mutex> lock(topology_);
      const Topic& t = topics_[topic];
      readers = t.readers;
      serialized = t.serialized;
    }
    for (Reader* r : readers) r->Deliver(bytes);
    for (SerializedReader* r : serialized) r->Deliver(bytes, stamp, sequence);
  }

  Log log_;
  bool spurious_ = false;
  std::mutex topology_;  // topics_ and the endpoint lists: threads write while another makes endpoints
  std::map<std::string, Topic> topics_;
  std::vector<std::unique_ptr<Reader>> readers_;
  std::vector<std::unique_ptr<Writer>> writers_;
  std::vector<std::unique_ptr<SerializedReader>> serialized_readers_;
  std::vector<std::unique_ptr<RawWriter>> serialized_writers_;
};

}  // namespace dyad::testing
