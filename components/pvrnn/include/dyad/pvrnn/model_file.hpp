// dyad/pvrnn/model_file.hpp: dyad's own model file (.dpvrnn): one file, versioned,
// self-describing, checksummed.
//
// Format (all integers little-endian):
//   bytes 0..7    magic "DYADPVRN"
//   u32           format version (kModelFileVersion)
//   u32           flags (0)
//   u64           J = length of the JSON header
//   J bytes       JSON: spec (layers d/z/tau/w, output dofs/dsoft/sigma), steps, sequences,
//                 provenance, tensor table [{name, rows, cols, offset}] (offsets in doubles
//                 from the start of the payload), optional training state scalars
//   payload       IEEE-754 doubles, little-endian
//   u32           CRC-32 (zlib) of every byte before it
// Contract
// - `SaveModel` writes to `path.tmp` then renames, so a crash never leaves a half file.
// - `LoadModel` never crashes on bad input: a truncated, corrupted (checksum), wrong-magic,
//   wrong-version or inconsistent file gives a Status whose message starts with the path and
//   says what is wrong.
#pragma once

#include <string>

#include "dyad/pvrnn/model.hpp"

namespace dyad::pvrnn {

inline constexpr uint32_t kModelFileVersion = 1;

Status SaveModel(const Model& model, const std::string& path);
StatusOr<Model> LoadModel(const std::string& path);

}  // namespace dyad::pvrnn
