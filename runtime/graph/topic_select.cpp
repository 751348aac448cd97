#include <dyad/topic_select.hpp>
#include <dyad/join_list.hpp>

#include <algorithm>
#include <regex>

namespace dyad {

StatusOr<std::vector<std::string>> SelectTopics(const std::vector<std::string>& patterns,
                                                const std::vector<std::string>& available, const std::string& param,
                                                const std::vector<std::string>& default_excluded) {
  std::vector<bool> chosen(available.size(), false);
  if (patterns.empty()) {
    for (size_t i = 0; i < available.size(); ++i)
      chosen[i] = std::find(default_excluded.begin(), default_excluded.end(), available[i]) == default_excluded.end();
  }
  const std::string known = JoinList(available);
  for (size_t p = 0; p < patterns.size(); ++p) {
    const std::string& pat = patterns[p];
    const std::string where = param + "[" + std::to_string(p) + "] = '" + pat + "'";
    bool any = false;
    auto exact = std::find(available.begin(), available.end(), pat);
    if (exact != available.end()) {
      chosen[static_cast<size_t>(exact - available.begin())] = true;
      continue;
    }
    std::regex re;
    try {
      re = std::regex(pat, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      return Status::InvalidArgument(where + ": neither a topic nor a valid regular expression (" + e.what() + ")");
    }
    for (size_t i = 0; i < available.size(); ++i)
      if (std::regex_match(available[i], re)) chosen[i] = any = true;
    if (!any) return Status::InvalidArgument(where + ": matches no topic (topics: " + (known.empty() ? "none" : known) + ")");
  }
  std::vector<std::string> out;
  for (size_t i = 0; i < available.size(); ++i)
    if (chosen[i]) out.push_back(available[i]);
  return out;
}

}  // namespace dyad
