// tools/support/text_output.hpp: what the commands that write tables share.
//
// CsvCell(text): the cell as RFC 4180 wants it: quoted (quotes doubled) when it holds a comma, a
// quote or a line break, else as it is. tests/support's ReadCsv reads it back.
// MarkdownCell(text): text for a Markdown table cell: '|' escaped (it would end the cell), line
// breaks as spaces (they would end the row).
// WriteTextFile(path, text): writes (truncating) the whole file; IOError naming the path when it
// cannot be opened or written.
#pragma once

#include <string>

#include "dyad/status.hpp"

namespace dyad::tools {

std::string CsvCell(const std::string& text);
std::string MarkdownCell(const std::string& text);
Status WriteTextFile(const std::string& path, const std::string& text);

}  // namespace dyad::tools
