// The text of `dyad bag info`: what a recording holds, and how much of it survived.
#pragma once

#include <string>

#include "dyad/mcap/reader.hpp"

namespace dyad::bag {

// A multi-line, human-readable report on an opened recording (ends with a newline).
std::string FormatInfo(const mcap::Reader& reader);

// "1700000000.123456789 (2023-11-14T22:13:20Z)": ns since the Unix epoch, exact, with its date.
std::string FormatTime(std::uint64_t ns, bool simulated = false);

}  // namespace dyad::bag
