// parallel_ranges (detail/thread_pool.h): the ranges a body sees depend only on
// n and the thread count, never on whether the pool was free at the time.
// parallel_items: every item once, whatever thread takes it; after a throw no
// item starts and the exception reaches the caller.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <stdexcept>
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

  TEST_CASE("parallel_items: every item exactly once, one at a time; a throw stops the hand-out and is rethrown") {
    // Items of very uneven cost (the first ones slow), as a layout's patches:
    // each is made once, its result at its index.
    const std::size_t n = 200;
    std::vector<std::atomic<int>> made(n);
    std::vector<std::size_t> result(n, 0);
    tspline::detail::parallel_items(n, tspline::detail::pool_threads(), [&](std::size_t k) {
      if (k < 4) std::this_thread::sleep_for(std::chrono::milliseconds(5));
      ++made[k];
      result[k] = k * k;
    });
    for (std::size_t k = 0; k < n; ++k) {
      CHECK(made[k] == 1);
      CHECK(result[k] == k * k);
    }
    // One thread, or fewer items than min_parallel: in order, in the caller.
    std::vector<std::size_t> order;
    const std::thread::id me = std::this_thread::get_id();
    tspline::detail::parallel_items(5, 1, [&](std::size_t k) {
      CHECK(std::this_thread::get_id() == me);
      order.push_back(k);
    });
    CHECK(order == std::vector<std::size_t>{0, 1, 2, 3, 4});
    order.clear();
    tspline::detail::parallel_items(3, tspline::detail::pool_threads(), [&](std::size_t k) { order.push_back(k); }, 4);
    CHECK(order == std::vector<std::size_t>{0, 1, 2});
    // Item 10 throws: the caller gets its exception and the hand-out stops.
    // One thread: items 0 to 10 started, in order. On the pool: items of 1 ms
    // each, so that the few an other thread starts while the exception
    // unwinds (microseconds) leave most of the 200 never started.
    std::atomic<std::size_t> started{0};
    auto throwing = [&](std::size_t k) {
      ++started;
      if (k == 10) throw std::runtime_error("item 10");
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    };
    CHECK_THROWS_WITH_AS(tspline::detail::parallel_items(200, 1, throwing), "item 10", std::runtime_error);
    CHECK(started == 11);
    started = 0;
    CHECK_THROWS_WITH_AS(tspline::detail::parallel_items(200, tspline::detail::pool_threads(), throwing), "item 10",
                         std::runtime_error);
    CHECK(started >= 11);
    CHECK(started < 100);
  }

  TEST_CASE("LentCore: where the cores lent leave the pool one, the same ranges run in the caller") {
    const int threads = tspline::detail::pool_threads();
    const std::size_t n = 1001;
    const std::vector<Range> free_pool = ranges_seen(n);
    auto run = [&](std::vector<std::thread::id>& ran_on) {
      std::mutex m;
      std::vector<Range> seen;
      tspline::detail::parallel_ranges(n, threads, [&](std::size_t b, std::size_t e, int slot) {
        std::lock_guard<std::mutex> lock(m);
        seen.emplace_back(b, e, slot);
        ran_on.push_back(std::this_thread::get_id());
      });
      return seen;
    };
    const std::thread::id me = std::this_thread::get_id();
    {
      // All but one of the pool's cores lent: the caller runs every range.
      std::vector<std::unique_ptr<tspline::detail::LentCore>> lent;
      for (int k = 0; k + 1 < threads; ++k) lent.push_back(std::make_unique<tspline::detail::LentCore>());
      std::vector<std::thread::id> ran_on;
      CHECK(run(ran_on) == free_pool);  // in slot order, one after the other
      for (const auto& id : ran_on) CHECK(id == me);
    }
    // Given back: the pool's threads again (the ranges the same).
    std::vector<std::thread::id> ran_on;
    std::vector<Range> again = run(ran_on);
    std::sort(again.begin(), again.end(),
              [](const Range& a, const Range& b) { return std::get<2>(a) < std::get<2>(b); });
    CHECK(again == free_pool);
    if (threads >= 2)
      CHECK(std::any_of(ran_on.begin(), ran_on.end(), [&](const auto& id) { return id != me; }));
  }

  TEST_CASE(
      "wait_while_one_core_left: returns when the lent cores are given back, or at once when stop() holds") {
    const int threads = tspline::detail::pool_threads();
    CHECK(!tspline::detail::one_core_left());
    tspline::detail::wait_while_one_core_left([] { return false; });  // nothing lent: returns at once
    std::atomic<bool> returned{false};
    std::thread waiter;
    {
      std::vector<std::unique_ptr<tspline::detail::LentCore>> lent;
      for (int k = 0; k < std::max(1, threads - 1); ++k)
        lent.push_back(std::make_unique<tspline::detail::LentCore>());
      CHECK(tspline::detail::one_core_left());
      tspline::detail::wait_while_one_core_left([] { return true; });  // stop(): returns at once
      waiter = std::thread([&] {
        tspline::detail::wait_while_one_core_left([] { return false; });
        returned = true;
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
      CHECK(!returned);  // still lent
    }
    waiter.join();  // returns once the last LentCore has ended
    CHECK(returned);
    CHECK(!tspline::detail::one_core_left());
  }
}
