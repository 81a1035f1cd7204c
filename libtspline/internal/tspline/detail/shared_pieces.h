#pragma once
// Pieces of several files made together and handed to each file's writer
// (multipatch_output.cpp: surface.vtu, surface_bezier.vtu and
// physical_tmesh.vtu from one Bezier extraction per patch).
//
// Each file's lane (a thread) takes its pieces in order, 0, 1, ... (VTK asks
// for them so). The lane that asks for a piece nobody has made yet makes it,
// for every file, outside the lock. A lane may make a piece only while it is
// at most `ahead` pieces beyond the slowest lane, so at most ahead + 1 pieces
// of every file wait in memory whatever the lanes' speeds. Once an error is
// raised (by make, or by a lane through fail()), every waiting and later
// take() rethrows it: no lane waits for one that has stopped.
#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "toolkit/errors.h"

namespace tspline::detail {

template <class Piece>
class SharedPieces {
 public:
  /// make(i): piece i of every file, one per file, in the files' order.
  using Make = std::function<std::vector<Piece>(int)>;
  SharedPieces(int pieces, std::size_t files, int ahead, Make make)
      : slots_(static_cast<std::size_t>(std::max(pieces, 0))),
        taken_(files, 0),
        ahead_(std::max(ahead, 0)),
        make_(std::move(make)) {}

  /// Piece i of file f; each file's lane asks for 0, 1, ... in turn.
  /// \throw InternalError if asked out of order; the first error raised.
  Piece take(std::size_t f, int i) {
    std::unique_lock<std::mutex> lock(m_);
    if (f >= taken_.size() || i < 0 || static_cast<std::size_t>(i) >= slots_.size() || i != taken_[f])
      throw toolkit::InternalError("SharedPieces: piece " + std::to_string(i) + " of file " +
                                   std::to_string(f) + " asked for out of order");
    for (;;) {
      if (error_) std::rethrow_exception(error_);
      Slot& slot = slots_[static_cast<std::size_t>(i)];
      if (slot.ready) {
        Piece out = std::move(slot.pieces[f]);
        ++taken_[f];
        if (++slot.taken == taken_.size()) slot.pieces.clear(), slot.pieces.shrink_to_fit();
        changed_.notify_all();
        return out;
      }
      const int slowest = *std::min_element(taken_.begin(), taken_.end());
      if (!slot.making && i - slowest <= ahead_) {
        slot.making = true;
        lock.unlock();
        std::vector<Piece> made;
        try {
          made = make_(i);
          if (made.size() != taken_.size())
            throw toolkit::InternalError("SharedPieces: make gave " + std::to_string(made.size()) +
                                         " pieces for " + std::to_string(taken_.size()) + " files");
        } catch (...) {
          fail(std::current_exception());
          throw;
        }
        lock.lock();
        slot.pieces = std::move(made);
        slot.ready = true;
        ++made_;
        changed_.notify_all();
        continue;
      }
      changed_.wait(lock);
    }
  }

  /// Raises e in every lane (the first error raised is kept).
  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(m_);
    if (!error_) error_ = e;
    changed_.notify_all();
  }

  /// Pieces made so far (each once).
  int made() const {
    std::lock_guard<std::mutex> lock(m_);
    return made_;
  }

 private:
  struct Slot {
    std::vector<Piece> pieces;
    bool making = false, ready = false;
    std::size_t taken = 0;
  };
  mutable std::mutex m_;
  std::condition_variable changed_;
  std::vector<Slot> slots_;
  std::vector<int> taken_;
  int ahead_;
  int made_ = 0;
  Make make_;
  std::exception_ptr error_;
};

}  // namespace tspline::detail
