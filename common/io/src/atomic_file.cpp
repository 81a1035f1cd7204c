#include "toolkit/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "toolkit/errors.h"

namespace toolkit::io {
namespace {

namespace fs = std::filesystem;

std::atomic<unsigned long> g_temp_counter{0};

std::string errno_text(int err) { return std::strerror(err); }

[[noreturn]] void fail(const std::string& what, const std::string& path, const std::string& reason) {
  throw IoError(what + " '" + path + "': " + reason);
}

/// Creates a new, empty file with a unique name ".NAME.tmp.PID.N" next to
/// `target` (O_CREAT|O_EXCL, so an existing file is never reused) and returns
/// its path. \throw IoError naming `target` if the file cannot be created.
std::string create_temp_next_to(const fs::path& target) {
  const fs::path name = target.filename();
  if (name.empty() || name == "." || name == "..") fail("cannot write", target.string(), "not a file name");
  const fs::path dir = target.parent_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    const unsigned long n = g_temp_counter.fetch_add(1, std::memory_order_relaxed);
    // Appended piecewise: GCC 12 warns (-Wrestrict, a false positive) on the chained operator+.
    std::string tmp_name = ".";
    tmp_name += name.string();
    tmp_name += ".tmp.";
    tmp_name += std::to_string(static_cast<long>(::getpid()));
    tmp_name += '.';
    tmp_name += std::to_string(n);
    const fs::path tmp = dir.empty() ? fs::path(tmp_name) : dir / tmp_name;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return tmp.string();
    }
    const int err = errno;
    if (err == EEXIST) continue;  // left over by a crashed process with a recycled PID
    fail("cannot write", target.string(), errno_text(err));
  }
  fail("cannot write", target.string(), "could not find an unused temporary file name");
}

void remove_quietly(const std::string& p) noexcept {
  std::error_code ec;
  fs::remove(p, ec);
}

}  // namespace

void write_atomic(const std::string& path, const std::function<void(const std::string& tmp_path)>& write) {
  const std::string tmp = create_temp_next_to(fs::path(path));
  try {
    write(tmp);
    std::error_code ec;
    if (!fs::is_regular_file(tmp, ec)) fail("cannot write", path, "the temporary file was not produced");
    fs::rename(tmp, path, ec);
    if (ec) fail("cannot write", path, ec.message());
  } catch (...) {
    remove_quietly(tmp);
    throw;
  }
}

void write_text_atomic(const std::string& path, const std::string& content) {
  write_atomic(path, [&](const std::string& tmp) {
    errno = 0;
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot write", path, errno != 0 ? errno_text(errno) : "cannot open the temporary file");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) fail("cannot write", path, errno != 0 ? errno_text(errno) : "write failed");
    out.close();
    if (out.fail()) fail("cannot write", path, errno != 0 ? errno_text(errno) : "close failed");
  });
}

void ensure_writable_directory(const std::string& dir) {
  const fs::path d = dir.empty() ? fs::path(".") : fs::path(dir);
  std::error_code ec;
  fs::create_directories(d, ec);
  if (ec) fail("cannot create directory", dir, ec.message());
  if (!fs::is_directory(d, ec)) fail("cannot use directory", dir, ec ? ec.message() : "not a directory");

  // Probe: access(W_OK) is meaningless for root and read-only mounts, so really
  // create (and remove) a file.
  const std::string probe_name = ".tspline_probe." + std::to_string(static_cast<long>(::getpid())) + "." +
                                 std::to_string(g_temp_counter.fetch_add(1, std::memory_order_relaxed));
  const fs::path probe = d / probe_name;
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    fail("directory is not writable", dir, errno_text(err));
  }
  ::close(fd);
  fs::remove(probe, ec);
  if (ec) fail("directory is not writable", dir, "cannot remove probe file: " + ec.message());
}

void check_writable_directory(const std::string& dir) {
  std::error_code ec;
  const fs::path p = fs::absolute(fs::path(dir), ec);
  if (ec) throw IoError("cannot use output directory " + dir + ": " + ec.message());
  auto writable = [](const fs::path& d) { return ::access(d.c_str(), W_OK | X_OK) == 0; };
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec))
      throw IoError("output directory " + dir + " exists and is not a directory");
    if (!writable(p))
      throw IoError("output directory " + dir + " is not writable: " + std::strerror(errno));
    return;
  }
  fs::path a = p.parent_path();
  while (!a.empty() && a != a.root_path() && !fs::exists(a, ec)) a = a.parent_path();
  if (a.empty()) a = p.root_path();
  if (!fs::is_directory(a, ec))
    throw IoError("cannot create output directory " + dir + ": " + a.string() +
                           " is not a directory");
  if (!writable(a))
    throw IoError("cannot create output directory " + dir + ": " + a.string() +
                           " is not writable: " + std::strerror(errno));
}

}  // namespace toolkit::io
