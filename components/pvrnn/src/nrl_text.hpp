// Internal: the plain-text pieces of NRL/VCBot files (data set rows, matrix lines, property
// lists), parsed in one place so that every reader accepts and rejects the same text.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dyad::pvrnn::internal {

// `s` without leading and trailing blanks (space, tab, CR, LF).
std::string_view Trim(std::string_view s);

// Comma-separated numbers, each field a whole decimal number (blanks around it allowed; one
// trailing comma allowed). Returns false on an empty or malformed field and, unless `bad` is
// null, stores that field. `out` is cleared first. NaN and infinities are rejected.
bool ParseNumberList(std::string_view line, std::vector<double>* out, std::string* bad = nullptr);

// A whole number in [lo, hi], nothing else (blanks around it allowed).
bool ParseInteger(std::string_view s, int64_t lo, int64_t hi, int64_t* out);

}  // namespace dyad::pvrnn::internal
