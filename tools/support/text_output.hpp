// tools/support/text_output.hpp: what the commands that write tables share.
//
// CsvCell(text): the cell as RFC 4180 wants it: quoted (quotes doubled) when it holds a comma, a
// quote or a line break, else as it is. tests/support's ReadCsv reads it back.
// MarkdownCell(text): text for a Markdown table cell: '|' escaped (it would end the cell), line
// breaks as spaces (they would end the row).
// CsvNumber(v): a number as every CSV of dyad prints it: the shortest text that reads back to the
// same double (std::to_chars; "0.1", "1e-07", "0.30000000000000004"), so a mean recomputed from a
// table's rows is the mean the tool computed, bit for bit. NaN (no value) is the empty cell;
// infinities are "inf" and "-inf" (what strtod and Python's float() read).
// WriteTextFile(path, text): writes (truncating) the whole file; IOError naming the path when it
// cannot be opened or written.
#pragma once

#include <string>

#include "dyad/status.hpp"

namespace dyad::tools {

std::string CsvCell(const std::string& text);
std::string MarkdownCell(const std::string& text);
std::string CsvNumber(double v);
Status WriteTextFile(const std::string& path, const std::string& text);

}  // namespace dyad::tools
