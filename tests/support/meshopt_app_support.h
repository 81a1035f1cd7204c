#pragma once
// Running the meshopt program in the end-to-end tests, and the check every
// bad-input case shares: exit 1, one line on stderr naming the problem, no output.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_support.h"

namespace meshopt_app_test {

inline test_support::AppRun run_meshopt(const std::string& args, const std::filesystem::path& dir) {
  return test_support::run_app(args, dir, MESHOPT_APP_PATH);
}

struct BadInput {
  std::string args, message;
};

/// Each case exits 1 with one line on stderr containing its message, and `output` is not written.
inline void check_bad_inputs(const std::vector<BadInput>& cases, const std::filesystem::path& dir,
                             const std::filesystem::path& output) {
  for (const BadInput& c : cases) {
    CAPTURE(c.args);
    const auto r = run_meshopt(c.args, dir);
    CAPTURE(r.err);
    CHECK(r.exit_code == 1);
    CHECK(test_support::contains(r.err, c.message));
    CHECK(test_support::count_lines(r.err) == 1);
    CHECK(!std::filesystem::exists(output));
  }
}

}  // namespace meshopt_app_test
