// tools/study/latin_square.hpp: the order of a study's conditions per participant, balanced for
// carry-over (Williams, 1949): a balanced Latin square.
//
// Contract of BalancedLatinSquare(n), n >= 1:
//   - Rows of the conditions 0..n-1, each row a permutation of them: n rows when n is even,
//     2n when n is odd (the square and its mirror image).
//   - Every condition comes at every position equally often (once per n rows).
//   - Every condition is followed by every other one equally often: once over the n rows (n
//     even), twice over the 2n rows (n odd). So no condition's effect carries into another more
//     often than any other.
//   - Participant i (0-based, in the study file's order) takes row i mod rows: a full balance
//     needs a multiple of rows participants (the study plan says so when it is not).
#pragma once

#include <vector>

namespace dyad::study {

std::vector<std::vector<int>> BalancedLatinSquare(int n);

}  // namespace dyad::study
