// dyad/pvrnn/analytic_dataset.hpp: a built-in data set needing no files, for demos and tests.
//
// Seven closed drawing primitives (circle, square, triangle, figure eight, star, heart,
// trefoil), 72 steps each at 100 ms, 2 DOF in workspace units, all within -45..45 (the
// -50..50 code range with a margin). Each primitive ends where it starts.
#pragma once

#include "dyad/pvrnn/dataset.hpp"

namespace dyad::pvrnn {

Dataset MakeAnalyticDataset();

}  // namespace dyad::pvrnn
