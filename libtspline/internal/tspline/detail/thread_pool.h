#pragma once
// One pool of worker threads for the whole process (before it, the map's
// energy, gradient and Hessian started threads for every evaluation).
// The workers are started on first use and live until exit; a parallel call
// hands each worker one contiguous range and waits for all of them.
//
// A call made while the pool is busy (another thread's call in flight, or a
// call from inside a range body) runs serially in the calling thread instead
// of waiting or oversubscribing the cores: callers that are themselves
// parallel (corner trials) keep their own parallelism.
#include <cstddef>
#include <functional>

namespace tspline::detail {

/// std::thread::hardware_concurrency(), at least 1, read once (glibc reads
/// /sys at every call: 3 % of a report's bounds over 9,216 patches).
unsigned hardware_threads();

/// Threads the pool can use (hardware_threads(), at most 16).
int pool_threads();

/// Runs body(begin, end, slot) on min(threads, pool_threads()) contiguous
/// ranges of [0, n), slot in [0, ranges); returns when all are done. One range
/// (slot 0) if threads <= 1, n < min_parallel or inside a pool's range. If the
/// pool is busy with another caller's work, the same ranges run one after the
/// other in the caller: the ranges never depend on timing, so neither does a
/// result combined from per-slot parts (auto's single patch, tried while the
/// layout's rotations use the pool, gave other last digits from run to run).
/// Exceptions from a body are rethrown in the caller (the first one).
void parallel_ranges(std::size_t n, int threads, const std::function<void(std::size_t, std::size_t, int)>& body,
                     std::size_t min_parallel = 256);

/// Runs item(k) for every k in [0, n) on min(threads, pool_threads()) of the
/// pool's threads, the items handed out one at a time as threads come free:
/// for independent items of uneven cost (the patches of a layout, whose sizes
/// vary along it), where contiguous ranges (parallel_ranges) can leave one
/// thread working alone at the end (the report's bounds of Newfoundland's
/// 8,776 patches: 1.5 s of its 4 s on one thread). An item's result must not
/// depend on the thread that makes it. In order in the caller if threads <= 1
/// or n < min_parallel. After an item throws, no further item starts; the
/// first exception is rethrown in the caller.
void parallel_items(std::size_t n, int threads, const std::function<void(std::size_t)>& item,
                    std::size_t min_parallel = 2);

/// While one lives, parallel_ranges calls of this thread run their ranges one
/// after the other in it (the ranges of a pool call, so the same results):
/// for threads that are themselves one of several busy workers (the patches
/// of a layout), where handing a small call's ranges to the pool costs more
/// than it gains.
class SerialRanges {
 public:
  SerialRanges();
  ~SerialRanges();
  SerialRanges(const SerialRanges&) = delete;
  SerialRanges& operator=(const SerialRanges&) = delete;

 private:
  bool previous_;
};

/// While one lives, a core is counted as busy outside the pool (a child
/// process at work, such as the quad mesher's): where that leaves the pool
/// one thread, parallel_ranges calls run their ranges one after the other in
/// the caller (the same ranges, so the same results), instead of two threads
/// sharing the one core left with the child. (Newfoundland: the mesher waited
/// for a core while auto's single-patch try ran on two.)
class LentCore {
 public:
  LentCore();
  ~LentCore();
  LentCore(const LentCore&) = delete;
  LentCore& operator=(const LentCore&) = delete;
};

/// Whether the cores lent (LentCore) leave the pool at most one.
bool one_core_left();

/// Blocks while one_core_left() and not stop(): for a thread of one's own
/// (one of several working through independent items) that should not share
/// the last core with a lent one. Woken when a LentCore ends; stop() is read
/// again every few milliseconds.
void wait_while_one_core_left(const std::function<bool()>& stop);

}  // namespace tspline::detail
