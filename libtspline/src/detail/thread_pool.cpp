// The process-wide worker pool; see thread_pool.h.
#include "tspline/detail/thread_pool.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace tspline::detail {

namespace {

// True on a worker, and on a caller while its own range runs: a nested call
// must not try the busy lock it may already hold.
thread_local bool inside_pool = false;
// Set by SerialRanges: this thread's calls take the busy path.
thread_local bool serial_ranges = false;
// Cores busy outside the pool (LentCore), and what wait_while_one_core_left waits on.
std::atomic<int> cores_lent{0};
std::mutex lent_mutex;
std::condition_variable lent_returned;

class Pool {
 public:
  explicit Pool(int threads) : size_(threads) {
    for (int t = 1; t < size_; ++t) workers_.emplace_back([this, t] { work(t); });
  }
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    start_.notify_all();
    for (std::thread& w : workers_) w.join();
  }
  int size() const { return size_; }

  // False (nothing done) if another call is in flight.
  bool run(std::size_t n, int ranges, const std::function<void(std::size_t, std::size_t, int)>& body) {
    std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
    if (!busy.owns_lock()) return false;
    const std::size_t chunk = (n + ranges - 1) / ranges;
    {
      std::lock_guard<std::mutex> lock(m_);
      body_ = &body;
      n_ = n, chunk_ = chunk, ranges_ = ranges;
      pending_ = ranges - 1;
      error_ = nullptr;
      ++generation_;
    }
    start_.notify_all();
    std::exception_ptr mine;
    inside_pool = true;
    try {
      body(0, std::min(n, chunk), 0);
    } catch (...) {
      mine = std::current_exception();
    }
    inside_pool = false;
    std::unique_lock<std::mutex> lock(m_);
    done_.wait(lock, [this] { return pending_ == 0; });
    body_ = nullptr;
    const std::exception_ptr err = mine ? mine : error_;
    lock.unlock();
    if (err) std::rethrow_exception(err);
    return true;
  }

 private:
  void work(int slot) {
    inside_pool = true;
    unsigned long seen = 0;
    for (;;) {
      std::unique_lock<std::mutex> lock(m_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (slot >= ranges_) continue;  // this call uses fewer ranges
      const auto* body = body_;
      const std::size_t b = std::min(n_, slot * chunk_), e = std::min(n_, (slot + 1) * chunk_);
      lock.unlock();
      std::exception_ptr err;
      try {
        (*body)(b, e, slot);
      } catch (...) {
        err = std::current_exception();
      }
      lock.lock();
      if (err && !error_) error_ = err;
      if (--pending_ == 0) done_.notify_one();
    }
  }

  int size_;
  std::vector<std::thread> workers_;
  std::mutex busy_;  // held for a whole call
  std::mutex m_;
  std::condition_variable start_, done_;
  const std::function<void(std::size_t, std::size_t, int)>* body_ = nullptr;
  std::size_t n_ = 0, chunk_ = 0;
  int ranges_ = 0, pending_ = 0;
  unsigned long generation_ = 0;
  std::exception_ptr error_;
  bool stop_ = false;
};

Pool& pool() {
  static Pool p(pool_threads());
  return p;
}

}  // namespace

unsigned hardware_threads() {
  static const unsigned n = std::max(1u, std::thread::hardware_concurrency());
  return n;
}

int pool_threads() {
  static const int n = std::min(static_cast<int>(hardware_threads()), 16);
  return n;
}

void parallel_ranges(std::size_t n, int threads, const std::function<void(std::size_t, std::size_t, int)>& body,
                     std::size_t min_parallel) {
  const int ranges = std::min(threads, pool_threads());
  if (ranges > 1 && n >= min_parallel && !inside_pool) {
    if (!serial_ranges && !one_core_left() && pool().run(n, ranges, body)) return;
    // Busy: the same ranges here, in slot order (as the pool's caller, nested
    // calls inside them run as one range).
    const std::size_t chunk = (n + ranges - 1) / ranges;
    inside_pool = true;
    try {
      for (int r = 0; r < ranges; ++r)
        body(std::min(n, static_cast<std::size_t>(r) * chunk), std::min(n, static_cast<std::size_t>(r + 1) * chunk), r);
    } catch (...) {
      inside_pool = false;
      throw;
    }
    inside_pool = false;
    return;
  }
  body(0, n, 0);
}

SerialRanges::SerialRanges() : previous_(serial_ranges) { serial_ranges = true; }
LentCore::LentCore() { cores_lent.fetch_add(1); }
LentCore::~LentCore() {
  {
    const std::lock_guard<std::mutex> lock(lent_mutex);
    cores_lent.fetch_sub(1);
  }
  lent_returned.notify_all();
}

bool one_core_left() { return cores_lent.load() > 0 && pool_threads() - cores_lent.load() <= 1; }

void wait_while_one_core_left(const std::function<bool()>& stop) {
  std::unique_lock<std::mutex> lock(lent_mutex);
  while (one_core_left() && !stop()) lent_returned.wait_for(lock, std::chrono::milliseconds(5));
}
SerialRanges::~SerialRanges() { serial_ranges = previous_; }

void parallel_items(std::size_t n, int threads, const std::function<void(std::size_t)>& item,
                    std::size_t min_parallel) {
  const std::size_t slots =
      std::min(n, static_cast<std::size_t>(std::max(1, std::min(threads, pool_threads()))));
  if (slots <= 1 || n < min_parallel) {
    for (std::size_t k = 0; k < n; ++k) item(k);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  parallel_ranges(
      slots, static_cast<int>(slots),
      [&](std::size_t, std::size_t, int) {
        for (std::size_t k; !failed && (k = next.fetch_add(1)) < n;) {
          try {
            item(k);
          } catch (...) {
            failed = true;
            throw;
          }
        }
      },
      1);
}

}  // namespace tspline::detail
