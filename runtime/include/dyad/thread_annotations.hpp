// dyad/thread_annotations.hpp — lock discipline the compiler checks (clang's -Wthread-safety,
// as LevelDB's port/thread_annotations.h). A member written "guarded by mu_" in a comment is
// declared GUARDED_BY(mu_) instead, and a function that expects a lock held says REQUIRES(mu_):
// clang then refuses a read or a write of that member, or a call of that function, without
// the lock. The sanitizer build (clang, tools/check.sh) compiles with -Wthread-safety
// -Werror=thread-safety; with gcc the macros expand to nothing and the types below are plain
// std::mutex and its guards, at no cost.
//
//   class Counter {
//    public:
//     void Add() EXCLUDES(mutex_) { MutexLock lock(mutex_); ++n_; }
//    private:
//     void AddLocked() REQUIRES(mutex_) { ++n_; }
//     Mutex mutex_;
//     int n_ GUARDED_BY(mutex_) = 0;
//   };
//
// Mutex: a std::mutex that clang knows as a capability. MutexLock: a std::lock_guard of it.
// UniqueLock: a std::unique_lock of it, for condition variables (native() is the unique_lock
// for std::condition_variable::wait; clang keeps counting the lock as held across the wait,
// which is what the code after the wait may assume). What the analysis cannot see (a lambda
// run under the lock by a wait predicate) says so with AssertHeld() rather than by turning it off.
#pragma once

#include <mutex>

#if defined(__clang__)
#define DYAD_THREAD_ANNOTATION(x) __attribute__((x))
#else
#define DYAD_THREAD_ANNOTATION(x)
#endif

#define CAPABILITY(x) DYAD_THREAD_ANNOTATION(capability(x))
#define SCOPED_CAPABILITY DYAD_THREAD_ANNOTATION(scoped_lockable)
#define GUARDED_BY(x) DYAD_THREAD_ANNOTATION(guarded_by(x))
#define PT_GUARDED_BY(x) DYAD_THREAD_ANNOTATION(pt_guarded_by(x))
#define ACQUIRED_BEFORE(...) DYAD_THREAD_ANNOTATION(acquired_before(__VA_ARGS__))
#define ACQUIRED_AFTER(...) DYAD_THREAD_ANNOTATION(acquired_after(__VA_ARGS__))
#define REQUIRES(...) DYAD_THREAD_ANNOTATION(requires_capability(__VA_ARGS__))
#define ACQUIRE(...) DYAD_THREAD_ANNOTATION(acquire_capability(__VA_ARGS__))
#define RELEASE(...) DYAD_THREAD_ANNOTATION(release_capability(__VA_ARGS__))
#define EXCLUDES(...) DYAD_THREAD_ANNOTATION(locks_excluded(__VA_ARGS__))
#define ASSERT_CAPABILITY(x) DYAD_THREAD_ANNOTATION(assert_capability(x))
#define NO_THREAD_SAFETY_ANALYSIS DYAD_THREAD_ANNOTATION(no_thread_safety_analysis)

namespace dyad {

class CAPABILITY("mutex") Mutex {
 public:
  Mutex() = default;
  Mutex(const Mutex&) = delete;
  Mutex& operator=(const Mutex&) = delete;

  void Lock() ACQUIRE() { mu_.lock(); }
  void Unlock() RELEASE() { mu_.unlock(); }
  // Tells the analysis the calling thread holds the lock (it is not checked at run time).
  void AssertHeld() const ASSERT_CAPABILITY(this) {}
  std::mutex& native() { return mu_; }

 private:
  std::mutex mu_;
};

class SCOPED_CAPABILITY MutexLock {
 public:
  explicit MutexLock(Mutex& mu) ACQUIRE(mu) : lock_(mu.native()) {}
  ~MutexLock() RELEASE() {}
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
};

class SCOPED_CAPABILITY UniqueLock {
 public:
  explicit UniqueLock(Mutex& mu) ACQUIRE(mu) : lock_(mu.native()) {}
  ~UniqueLock() RELEASE() {}
  UniqueLock(const UniqueLock&) = delete;
  UniqueLock& operator=(const UniqueLock&) = delete;

  void Lock() ACQUIRE() { lock_.lock(); }
  void Unlock() RELEASE() { lock_.unlock(); }
  std::unique_lock<std::mutex>& native() { return lock_; }

 private:
  std::unique_lock<std::mutex> lock_;
};

}  // namespace dyad
