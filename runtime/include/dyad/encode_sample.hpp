// EncodeSample — a typed message as CDR with its 4-byte encapsulation header, what
// SerializedWriter::Write takes: the counterpart of dyad/decode_sample.hpp's DecodeSample, through
// the same generated type support (MessageTraits<T>::PubSubType). Empty when it cannot be
// encoded (it always can for a message of a dyad IDL type). Thread-safe; builds the type support
// afresh each call: fine for a sample now and then (a live parameter request, a health event),
// not a hot loop. Used by components that write a runtime topic through a SerializedWriter.
#pragma once

#include <cstdint>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

#include <dyad/message_traits.hpp>
#include <dyad/msg/types_support.hpp>  // MessageTraits<T>::PubSubType, complete

namespace dyad {

template <class T>
std::vector<uint8_t> EncodeSample(const T& sample) {
  typename MessageTraits<T>::PubSubType support;
  void* data = const_cast<T*>(&sample);  // Fast DDS 2's serialize takes void*; it only reads
  try {
    eprosima::fastrtps::rtps::SerializedPayload_t payload(support.getSerializedSizeProvider(data)());
    if (!support.serialize(data, &payload)) return {};
    return std::vector<uint8_t>(payload.data, payload.data + payload.length);
  } catch (...) {  // fastcdr throws when the buffer is short: cannot happen with the size asked for
    return {};
  }
}

}  // namespace dyad
