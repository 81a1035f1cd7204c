// parallel_ranges (detail/thread_pool.h): the ranges a body sees depend only on
// n and the thread count, never on whether the pool was free at the time.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <tuple>
#include <vector>

#include "tspline/detail/thread_pool.h"

namespace {

using Range = std::tuple<std::size_t, std::size_t, int>;

std::vector<Range> ranges_seen(std::size_t n) {
  std::mutex m;
  std::vector<Range> seen;
  tspline::detail::parallel_ranges(n, tspline::detail::pool_threads(), [&](std::size_t b, std::size_t e, int slot) {
    std::lock_guard<std::mutex> lock(m);
    seen.emplace_back(b, e, slot);
  });
  std::sort(seen.begin(), seen.end(), [](const Range& a, const Range& b) { return std::get<2>(a) < std::get<2>(b); });
  return seen;
}

}  // namespace

TEST_SUITE("thread_pool") {
  TEST_CASE("the same contiguous ranges whether the pool is free or busy with another caller") {
    const int threads = tspline::detail::pool_threads();
    const std::size_t n = 1001;
    const std::vector<Range> free_pool = ranges_seen(n);
    // The partition: `threads` contiguous ranges of ceil(n / threads), slots in order, covering [0, n).
    REQUIRE(free_pool.size() == static_cast<std::size_t>(threads));
    const std::size_t chunk = (n + threads - 1) / threads;
    for (int r = 0; r < threads; ++r) {
      CHECK(std::get<0>(free_pool[r]) == std::min(n, r * chunk));
      CHECK(std::get<1>(free_pool[r]) == std::min(n, (r + 1) * chunk));
      CHECK(std::get<2>(free_pool[r]) == r);
    }
    if (threads < 2) return;  // one range either way: nothing more to see
    // Another thread holds the pool (its body waits until released); the
    // caller here must get the same ranges, run by itself.
    std::atomic<bool> holding{false}, release{false};
    std::thread other([&] {
      tspline::detail::parallel_ranges(2, 2, [&](std::size_t, std::size_t, int slot) {
        if (slot != 0) return;
        holding = true;
        while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }, 1);
    });
    while (!holding) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const std::thread::id me = std::this_thread::get_id();
    std::vector<std::thread::id> ran_on;
    std::mutex m;
    std::vector<Range> busy_pool;
    tspline::detail::parallel_ranges(n, threads, [&](std::size_t b, std::size_t e, int slot) {
      std::lock_guard<std::mutex> lock(m);
      busy_pool.emplace_back(b, e, slot);
      ran_on.push_back(std::this_thread::get_id());
    });
    release = true;
    other.join();
    CHECK(busy_pool == free_pool);  // in slot order, run one after the other
    for (const auto& id : ran_on) CHECK(id == me);
  }
}
