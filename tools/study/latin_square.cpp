#include "latin_square.hpp"

#include <cstddef>

namespace dyad::study {

std::vector<std::vector<int>> BalancedLatinSquare(int n) {
  // The first row is 0, 1, n-1, 2, n-2, ...; row r adds r to each (mod n).
  std::vector<int> first = {0};
  for (int k = 1, lo = 1, hi = n - 1; static_cast<int>(first.size()) < n; ++k) first.push_back(k % 2 == 1 ? lo++ : hi--);
  std::vector<std::vector<int>> rows;
  for (int r = 0; r < n; ++r) {
    std::vector<int> row;
    for (int c : first) row.push_back((c + r) % n);
    rows.push_back(row);
  }
  if (n % 2 == 1)
    for (int r = 0; r < n; ++r) {
      std::vector<int> mirrored(rows[static_cast<size_t>(r)].rbegin(), rows[static_cast<size_t>(r)].rend());
      rows.push_back(std::move(mirrored));  // a copy first: push_back may move the rows it reads
    }
  return rows;
}

}  // namespace dyad::study
