#include "internal/pair.hpp"

#include <omp.h>
#include <unistd.h>

#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

namespace dynid::detail {

namespace {

class Helper {
 public:
  Helper() : pid_(getpid()), thread_([this] { loop(); }) {}
  Helper(const Helper&) = delete;
  Helper& operator=(const Helper&) = delete;

  // const, with mutable members: its state is its synchronization (one shared helper, never modified from outside).
  bool run(const std::function<void()>& here, const std::function<void()>& there) const {
    if (getpid() != pid_ || !busy_.try_lock()) return false;
    {
      std::lock_guard<std::mutex> l(m_);
      job_ = &there;
      done_ = false;
    }
    cv_.notify_one();
    std::exception_ptr failed;
    try {
      here();
    } catch (...) {
      failed = std::current_exception();  // after the helper is done with there(), which lives in the caller
    }
    std::exception_ptr failed_there;
    {
      std::unique_lock<std::mutex> l(m_);
      done_cv_.wait(l, [&] { return done_; });
      failed_there = std::exchange(failed_, nullptr);
    }
    busy_.unlock();
    if (failed) std::rethrow_exception(failed);
    if (failed_there) std::rethrow_exception(failed_there);
    return true;
  }

 private:
  [[noreturn]] void loop() const {
    std::unique_lock<std::mutex> l(m_);
    for (;;) {
      cv_.wait(l, [&] { return job_ != nullptr; });
      const std::function<void()>* f = job_;
      job_ = nullptr;
      l.unlock();
      std::exception_ptr failed;
      try {
        (*f)();
      } catch (...) {
        failed = std::current_exception();  // to the caller, not out of this thread
      }
      l.lock();
      failed_ = failed;
      done_ = true;
      done_cv_.notify_one();
    }
  }
  pid_t pid_;
  mutable std::mutex m_, busy_;
  mutable std::condition_variable cv_, done_cv_;
  mutable const std::function<void()>* job_ = nullptr;
  mutable std::exception_ptr failed_;
  mutable bool done_ = false;
  std::thread thread_;
};

}  // namespace

void run_pair(const std::function<void()>& here, const std::function<void()>& there) {
  if (!omp_in_parallel() && omp_get_max_threads() > 1) {
    // Started on first use and left running (detached in effect) to the end of the process: it only ever sleeps
    // between calls, and a static destructor joining it could race with other static destructors.
    static const Helper* const helper = new Helper;
    if (helper->run(here, there)) return;
  }
  here();
  there();
}

}  // namespace dynid::detail
