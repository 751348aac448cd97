#include "hosts/process_run.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

#include "dyad/interrupt.hpp"

namespace dyad {

// A process that cannot stop must not outlive its launcher unseen: kStopGraceS after a signal
// it exits anyway, unless the run has ended by then (the guard is cancelled before this returns).
ProcessRun RunProcess(const Graph& graph, const ResolvedGraph& resolved, const Catalog& catalog, const Executor::Options& eo) {
  ProcessRun run;
  std::atomic<Executor*> current{nullptr};
  std::mutex guard_mutex;
  std::condition_variable guard_cv;
  bool run_over = false;
  std::thread guard;
  {
    InterruptWatcher interrupt([&](int sig) {
      if (Executor* ex = current.load()) ex->RequestStop(SignalName(sig));
      std::lock_guard<std::mutex> lock(guard_mutex);
      if (guard.joinable() || run_over) return;
      guard = std::thread([&, sig] {
        std::unique_lock<std::mutex> lock(guard_mutex);
        if (guard_cv.wait_for(lock, std::chrono::duration<double>(kStopGraceS), [&] { return run_over; })) return;
        std::fprintf(stderr, "dyad run: did not stop within %g s of %s: exiting without a clean shutdown\n", kStopGraceS,
                     SignalName(sig));
        std::_Exit(ExitCodeForSignal(sig));
      });
    });
    Executor ex(graph, resolved, &catalog, eo);
    current.store(&ex);
    if (interrupt.signal() != 0) ex.RequestStop(SignalName(interrupt.signal()));  // before `current` was set
    run.result = ex.Run();
    run.rows = ex.Report();
    run.mismatches = ex.wiring_problems();
    current.store(nullptr);
    run.signal = interrupt.signal();
    {
      std::lock_guard<std::mutex> lock(guard_mutex);
      run_over = true;
    }
    guard_cv.notify_all();
  }  // the signal thread has ended: `guard` is no longer written
  if (guard.joinable()) guard.join();
  return run;
}

}  // namespace dyad
