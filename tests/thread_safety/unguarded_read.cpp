// Compiled by the thread_safety_* tests (tests/CMakeLists.txt) with clang and -Wthread-safety:
// proves that dyad/thread_annotations.hpp's macros reach clang's analysis. Built as it is, the
// read of a GUARDED_BY member without its lock must be refused ("requires holding mutex");
// with -DDYAD_HOLD_THE_LOCK the same read under a MutexLock must compile cleanly.
#include <dyad/thread_annotations.hpp>

namespace {

class Counter {
 public:
  int Read() {
#ifdef DYAD_HOLD_THE_LOCK
    dyad::MutexLock lock(mutex_);
#endif
    return value_;
  }
  void Add() EXCLUDES(mutex_) {
    dyad::MutexLock lock(mutex_);
    AddLocked();
  }

 private:
  void AddLocked() REQUIRES(mutex_) { ++value_; }

  dyad::Mutex mutex_;
  int value_ GUARDED_BY(mutex_) = 0;
};

}  // namespace

int main() {
  Counter c;
  c.Add();
  return c.Read() == 1 ? 0 : 1;
}
