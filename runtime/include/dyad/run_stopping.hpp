// dyad/run_stopping.hpp — whether the run is ending, for a component that waits inside
// Activate() (the web component's wait for the subject's page, its wait_for_subject_s): such a
// wait must also end when the run is asked to stop (Ctrl-C or SIGTERM, a component's
// RequestStop, a failure), else the process outlives the request by as long as the wait.
//
// Contract:
//   - RunStopping(ctx): true once the run has been asked to stop, from any thread, at any time
//     between Configure() and Shutdown(); false before, and always for a Context that is not the
//     runtime's own (a test fake). Cheap (an atomic load): poll it in the wait's loop.
//
// Why a free function and not a Context method: adding a virtual to Context would change the
// plugin ABI (kPluginAbiVersion); see dyad/on_demand_subscription.hpp, which does the same.
//
//   while (!ready() && !dyad::RunStopping(ctx)) std::this_thread::sleep_for(10ms);
#pragma once

#include <dyad/component.hpp>

namespace dyad {

bool RunStopping(const Context& ctx);

namespace detail {
// Implemented by the runtime's own contexts (not for component code), reached through a
// dynamic_cast by RunStopping.
class RunStoppingQuery {
 public:
  virtual ~RunStoppingQuery() = default;
  virtual bool run_stopping() const = 0;
};
}  // namespace detail

}  // namespace dyad
