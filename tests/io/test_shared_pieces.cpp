// detail::SharedPieces (multipatch_output.cpp's three lanes of VTU files):
// every lane gets every piece of its file in order, each piece is made once,
// no lane runs more than `ahead` pieces beyond the slowest, and an error in
// one lane or in a piece's making reaches every lane instead of leaving one
// waiting.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "toolkit/errors.h"
#include "tspline/detail/shared_pieces.h"

using tspline::detail::SharedPieces;

namespace {

constexpr int kPieces = 12;
constexpr std::size_t kFiles = 3;

// Runs one thread per file; lane f sleeps delay[f] ms after each piece. The
// lanes' results (or errors); a lane still running after 60 s is a hang.
std::vector<std::string> run_lanes(SharedPieces<std::string>& shared, const std::array<int, kFiles>& delay,
                                   std::atomic<int>* progress = nullptr, int fail_lane = -1,
                                   int fail_at = -1) {
  std::vector<std::future<std::string>> lanes;
  for (std::size_t f = 0; f < kFiles; ++f)
    lanes.push_back(std::async(std::launch::async, [&, f]() -> std::string {
      std::string got;
      try {
        for (int i = 0; i < kPieces; ++i) {
          if (static_cast<int>(f) == fail_lane && i == fail_at) {
            const auto e =
                std::make_exception_ptr(std::runtime_error("lane " + std::to_string(f) + " failed"));
            shared.fail(e);
            std::rethrow_exception(e);
          }
          got += shared.take(f, i) + ";";
          if (progress) progress[f] = i + 1;
          std::this_thread::sleep_for(std::chrono::milliseconds(delay[f]));
        }
      } catch (const std::exception& e) {
        return std::string("error: ") + e.what();
      }
      return got;
    }));
  std::vector<std::string> out;
  for (auto& lane : lanes) {
    REQUIRE(lane.wait_for(std::chrono::seconds(60)) == std::future_status::ready);
    out.push_back(lane.get());
  }
  return out;
}

std::string expected(std::size_t f) {
  std::string s;
  for (int i = 0; i < kPieces; ++i) s += std::to_string(i) + "/" + std::to_string(f) + ";";
  return s;
}

}  // namespace

TEST_SUITE("shared_pieces") {
  TEST_CASE("every lane gets its pieces in order, each piece made once, no lane far ahead of the slowest") {
    for (const int ahead : {0, 1, 3}) {
      CAPTURE(ahead);
      std::atomic<int> progress[kFiles] = {};
      std::atomic<int> calls{0}, too_far{0};
      SharedPieces<std::string> shared(kPieces, kFiles, ahead, [&](int i) {
        ++calls;
        // The lanes record a piece after take() returns it (one behind at
        // most): piece i is made while the slowest has at least i - ahead.
        int slowest = kPieces;
        for (const auto& p : progress) slowest = std::min(slowest, p.load());
        if (i - slowest > ahead + 1) ++too_far;
        std::vector<std::string> out;
        for (std::size_t f = 0; f < kFiles; ++f) out.push_back(std::to_string(i) + "/" + std::to_string(f));
        return out;
      });
      // Lane 0 slow, lanes 1 and 2 fast: they must wait for it.
      const std::vector<std::string> got = run_lanes(shared, {3, 0, 0}, progress);
      for (std::size_t f = 0; f < kFiles; ++f) CHECK(got[f] == expected(f));
      CHECK(calls == kPieces);
      CHECK(shared.made() == kPieces);
      CHECK(too_far == 0);
    }
  }

  TEST_CASE("an error while a piece is made reaches every lane") {
    SharedPieces<std::string> shared(kPieces, kFiles, 1, [&](int i) {
      if (i == 5) throw std::runtime_error("piece 5 could not be made");
      return std::vector<std::string>(kFiles, std::to_string(i));
    });
    const std::vector<std::string> got = run_lanes(shared, {1, 0, 2});
    for (const std::string& g : got) CHECK(g == "error: piece 5 could not be made");
  }

  TEST_CASE("a lane that stops (fail) stops the lanes waiting for it") {
    SharedPieces<std::string> shared(
        kPieces, kFiles, 1, [&](int i) { return std::vector<std::string>(kFiles, std::to_string(i)); });
    const std::vector<std::string> got = run_lanes(shared, {0, 0, 0}, nullptr, 2, 4);
    for (const std::string& g : got) CHECK(g == "error: lane 2 failed");
  }

  TEST_CASE("pieces asked for out of order, and a make that gives the wrong count, are errors") {
    SharedPieces<std::string> shared(
        kPieces, kFiles, 1, [&](int i) { return std::vector<std::string>(kFiles, std::to_string(i)); });
    CHECK_THROWS_AS(shared.take(0, 1), toolkit::InternalError);
    CHECK(shared.take(0, 0) == "0");
    CHECK_THROWS_AS(shared.take(0, 0), toolkit::InternalError);  // (taken already)
    CHECK_THROWS_AS(shared.take(kFiles, 0), toolkit::InternalError);
    SharedPieces<std::string> short_make(2, kFiles, 1, [&](int) { return std::vector<std::string>(1, "x"); });
    CHECK_THROWS_AS(short_make.take(0, 0), toolkit::InternalError);
    CHECK_THROWS_AS(short_make.take(1, 0), toolkit::InternalError);  // the error is kept
  }
}
