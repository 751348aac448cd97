// The recorder plugin: `recorder` and `replay` (see recorder.hpp and replay.hpp).
#include "recorder.hpp"
#include "replay.hpp"

DYAD_PLUGIN(registry) {
  registry.Add<dyad::recorder::Recorder>("recorder");
  registry.Add<dyad::recorder::Replay>("replay");
}
