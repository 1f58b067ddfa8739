#pragma once
// A mutex with priority inheritance (PTHREAD_PRIO_INHERIT): while a thread of higher priority
// waits for it, its holder runs at that priority. gyrod's sample thread may run SCHED_FIFO and
// its client thread SCHED_OTHER; they share the daemon's state (pipeline, driver counters)
// through this mutex, held by the client thread only for the few microseconds it takes to copy
// a report. Without inheritance a SCHED_OTHER holder preempted on a busy CPU would keep the
// sample thread waiting for a whole scheduler slice or more (the classic priority inversion);
// with it, the sample thread waits at most for the holder's critical section. The socket
// server guards each client's buffer with one too, shared by the real-time delivery thread
// and the client thread (daemon/unix_socket_server.hpp). Satisfies Lockable
// (std::lock_guard, std::unique_lock).
#include <pthread.h>

#include <system_error>

namespace gyrod::daemon {

class PriorityInheritanceMutex {
 public:
  PriorityInheritanceMutex() {
    pthread_mutexattr_t attr;
    ::pthread_mutexattr_init(&attr);
    // Refused only where the kernel lacks PI futexes: then a plain mutex, still correct.
    ::pthread_mutexattr_setprotocol(&attr, PTHREAD_PRIO_INHERIT);
    const int rc = ::pthread_mutex_init(&mutex_, &attr);
    ::pthread_mutexattr_destroy(&attr);
    if (rc != 0) throw std::system_error(rc, std::generic_category(), "pthread_mutex_init");
  }
  ~PriorityInheritanceMutex() { ::pthread_mutex_destroy(&mutex_); }
  PriorityInheritanceMutex(const PriorityInheritanceMutex&) = delete;
  PriorityInheritanceMutex& operator=(const PriorityInheritanceMutex&) = delete;

  void lock() {
    if (const int rc = ::pthread_mutex_lock(&mutex_); rc != 0)
      throw std::system_error(rc, std::generic_category(), "pthread_mutex_lock");
  }
  bool try_lock() noexcept { return ::pthread_mutex_trylock(&mutex_) == 0; }
  void unlock() noexcept { ::pthread_mutex_unlock(&mutex_); }

 private:
  pthread_mutex_t mutex_;
};

}  // namespace gyrod::daemon
