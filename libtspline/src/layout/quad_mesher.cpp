#include "tspline/layout/quad_mesher.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <mutex>
#include <string>

#include "tspline/detail/quad_mesher_backend.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/errors.h"

namespace tspline {

#ifndef TSPLINE_HAVE_GMSH

bool quad_mesher_available() { return false; }

PlanarQuadMesh quad_mesh(const std::vector<std::vector<Eigen::Vector2d>>&,
                         const std::function<double(const Eigen::Vector2d&)>&) {
  throw InputError("automatic quad layouts need Gmsh, and this build has none (rebuild with libgmsh-dev installed "
                   "and TSPLINE_WITH_GMSH=ON), or give the cuts");
}

#else

bool quad_mesher_available() { return true; }

namespace {

// Gmsh keeps one global model: one layout at a time.
std::mutex gmsh_mutex;

// Whole writes and reads on a pipe: `io` (::read or ::write) until n bytes
// have gone, again after a signal; false at the end of the pipe or an error.
template <class Byte, class Io>
bool transfer_all(int fd, Byte* p, std::size_t n, Io io) {
  while (n > 0) {
    const ssize_t k = io(fd, p, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    p += k, n -= static_cast<std::size_t>(k);
  }
  return true;
}

bool write_all(int fd, const void* data, std::size_t n) {
  return transfer_all(fd, static_cast<const char*>(data), n, ::write);
}

template <class T>
bool write_vector(int fd, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  return write_all(fd, &n, sizeof n) && write_all(fd, v.data(), n * sizeof(T));
}

bool read_all(int fd, void* data, std::size_t n) { return transfer_all(fd, static_cast<char*>(data), n, ::read); }

template <class T>
bool read_vector(int fd, std::vector<T>& v) {
  std::uint64_t n = 0;
  if (!read_all(fd, &n, sizeof n) || n > (std::uint64_t{1} << 40) / sizeof(T)) return false;
  v.resize(n);
  return read_all(fd, v.data(), n * sizeof(T));
}

}  // namespace

// Gmsh 4.8 reports some meshing failures by throwing from inside its OpenMP
// regions, which terminates the process whatever the caller catches. So the
// mesh is made in a child process (fork) and sent back through a pipe; a
// child that fails or dies is a NumericalError here, and the caller goes on.
//
// Under AddressSanitizer the mesh is made in this process instead: the
// sanitizer's allocator (GCC 12) takes no locks around fork, so a child forked
// while another thread (auto's single-patch try) held one of them waits for
// it forever in its first malloc (a sanitized test run hung so). glibc's
// malloc takes its arena locks around fork, so the child is safe there.
PlanarQuadMesh quad_mesh(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                         const std::function<double(const Eigen::Vector2d&)>& size) {
  std::lock_guard<std::mutex> lock(gmsh_mutex);
  // (Loaded here, before any fork: a child must not load libraries.)
  const auto mesh_here = detail::quad_mesher_backend().mesh;
  // The mesher keeps a core busy (here, or in its child) while this thread
  // waits: the pool's callers meanwhile leave it that core.
  const detail::LentCore lent;
#if defined(__SANITIZE_ADDRESS__)
  return mesh_here(rings, size);
#endif
  int fds[2];
  if (::pipe(fds) != 0) throw NumericalError("the quad mesher could not open a pipe");
  std::cout.flush();
  std::cerr.flush();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw NumericalError("the quad mesher could not start its process");
  }
  if (pid == 0) {
    ::close(fds[0]);
    // Gmsh's exceptions from inside OpenMP regions end in std::terminate:
    // send their text (Gmsh throws std::string) as the child's error.
    // Gmsh's own messages and the runtime's go nowhere (the parent reports).
    const int null_fd = ::open("/dev/null", O_WRONLY);
    if (null_fd >= 0) ::dup2(null_fd, 2);
    static int error_fd = -1;
    error_fd = fds[1];
    std::set_terminate([] {
      std::string what = "Gmsh stopped";
      try {
        if (auto e = std::current_exception()) std::rethrow_exception(e);
      } catch (const std::string& s) {
        what += ": " + s;
      } catch (const std::exception& e) {
        what += std::string(": ") + e.what();
      } catch (...) {
      }
      const int failed = 1;
      std::vector<char> text(what.begin(), what.end());
      if (write_all(error_fd, &failed, sizeof failed)) write_vector(error_fd, text);
      std::_Exit(3);
    });
    int status = 0;
    std::string message;
    PlanarQuadMesh m;
    try {
      m = mesh_here(rings, size);
    } catch (const std::exception& e) {
      status = 1, message = e.what();
    } catch (...) {
      status = 1, message = "unknown error";
    }
    std::vector<double> xy;
    for (const auto& p : m.nodes) xy.push_back(p.x()), xy.push_back(p.y());
    std::vector<char> text(message.begin(), message.end());
    const bool ok = write_all(fds[1], &status, sizeof status) && write_vector(fds[1], text) &&
                    write_vector(fds[1], xy) && write_vector(fds[1], m.quads) && write_vector(fds[1], m.ring) &&
                    write_vector(fds[1], m.segment) && write_vector(fds[1], m.t);
    ::close(fds[1]);
    std::_Exit(ok ? 0 : 2);
  }
  ::close(fds[1]);
  int status = -1;
  std::vector<char> text;
  std::vector<double> xy;
  PlanarQuadMesh out;
  const bool ok = read_all(fds[0], &status, sizeof status) && read_vector(fds[0], text) && read_vector(fds[0], xy) &&
                  read_vector(fds[0], out.quads) && read_vector(fds[0], out.ring) &&
                  read_vector(fds[0], out.segment) && read_vector(fds[0], out.t);
  ::close(fds[0]);
  int wstatus = 0;
  while (::waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
  }
  if (status != 0 && !text.empty())
    throw NumericalError("the quad mesher (Gmsh) failed: " + std::string(text.begin(), text.end()));
  if (!ok) throw NumericalError("the quad mesher (Gmsh) failed on this layout (its process stopped)");
  for (std::size_t i = 0; i + 1 < xy.size(); i += 2) out.nodes.push_back({xy[i], xy[i + 1]});
  return out;
}

#endif

}  // namespace tspline
