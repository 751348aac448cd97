// dyad/decode_sample.hpp — a serialized sample (SerializedSample::cdr, a recording's bytes) as
// the typed message it carries, without the middleware's headers.
//
// Contract of DecodeSample(cdr, &sample):
//   - `cdr` is CDR with its 4-byte encapsulation header, as SerializedSample::cdr carries it and
//     as SerializedWriter::Write takes it.
//   - On success *sample holds the decoded message (every field, header included); on failure it
//     is unspecified and the Status is InvalidArgument naming the type and the byte count (short,
//     corrupt, or another type's bytes). Nothing throws.
//   - Thread-safe (no shared state). Each call builds the type's support afresh: fine for a
//     sample a second (dyad/stats), not for a hot loop.
//
//   Context::SubscribeSerialized("dyad/stats", [](const dyad::SerializedSample& s) {
//     dyad::msg::ComponentStats stats;
//     if (dyad::DecodeSample(s.cdr, &stats).ok()) Use(stats);
//   });
#pragma once

#include <cstdint>
#include <span>

#include <dyad/message_traits.hpp>
#include <dyad/status.hpp>

namespace dyad {

// Type-erased form: `sample` points to an object of `type` (TypeInfoOf<T>() for a T).
Status DecodeSample(std::span<const uint8_t> cdr, const TypeInfo& type, void* sample);

template <class T>
Status DecodeSample(std::span<const uint8_t> cdr, T* sample) {
  return DecodeSample(cdr, TypeInfoOf<T>(), sample);
}

}  // namespace dyad
