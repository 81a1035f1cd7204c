#include "tspline/layout/quad_mesher.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <mutex>
#include <string>
#include <unordered_map>

#include "tspline/detail/thread_pool.h"
#include "tspline/errors.h"

#ifdef TSPLINE_HAVE_GMSH
#include <gmsh.h>
#endif

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

struct GmshSession {
  GmshSession() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
    // One thread: Gmsh reports errors by throwing, which cannot leave its OpenMP regions.
    gmsh::option::setNumber("General.NumThreads", 1);
    gmsh::option::setNumber("Mesh.MaxNumThreads2D", 1);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

std::string gmsh_last_error() {
  std::string e;
  try {
    gmsh::logger::getLastError(e);
  } catch (...) {
  }
  return e.empty() ? "no message" : e;
}

// The mesh by Gmsh in this process (quad_mesh runs it in a child process).
PlanarQuadMesh quad_mesh_here(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                              const std::function<double(const Eigen::Vector2d&)>& size) {
  GmshSession session;
  PlanarQuadMesh out;
  try {
    gmsh::model::add("layout");
    std::vector<int> loops;
    // Point tag -> (ring, segment start); line tag -> (ring, segment).
    std::unordered_map<int, std::pair<int, int>> point_of, line_of;
    int next_point = 1, next_line = 1;
    for (std::size_t r = 0; r < rings.size(); ++r) {
      const auto& ring = rings[r];
      const int first = next_point;
      for (std::size_t k = 0; k < ring.size(); ++k) {
        gmsh::model::geo::addPoint(ring[k].x(), ring[k].y(), 0.0, 0.0, next_point);
        point_of[next_point++] = {static_cast<int>(r), static_cast<int>(k)};
      }
      std::vector<int> lines;
      for (std::size_t k = 0; k < ring.size(); ++k) {
        const int a = first + static_cast<int>(k), b = first + static_cast<int>((k + 1) % ring.size());
        gmsh::model::geo::addLine(a, b, next_line);
        line_of[next_line] = {static_cast<int>(r), static_cast<int>(k)};
        lines.push_back(next_line++);
      }
      loops.push_back(gmsh::model::geo::addCurveLoop(lines));
    }
    gmsh::model::geo::addPlaneSurface(loops, 1);
    for (const auto& [line, where] : line_of) gmsh::model::geo::mesh::setTransfiniteCurve(line, 2);
    gmsh::model::geo::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
    gmsh::option::setNumber("Mesh.Algorithm", 6);               // Frontal-Delaunay
    gmsh::option::setNumber("Mesh.RecombineAll", 1);
    gmsh::option::setNumber("Mesh.RecombinationAlgorithm", 1);  // Blossom
    gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", 1);    // all quadrilaterals
    gmsh::option::setNumber("Mesh.Smoothing", 10);
    // The mesh is split once at the end: mesh at twice the final size.
    gmsh::model::mesh::setSizeCallback(
        [&size](int, int, double x, double y, double) { return 2.0 * size(Eigen::Vector2d(x, y)); });
    gmsh::model::mesh::generate(2);

    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(tags, coord, param, -1, -1, false, false);
    std::unordered_map<std::size_t, int> index;
    for (std::size_t i = 0; i < tags.size(); ++i) {
      index[tags[i]] = static_cast<int>(out.nodes.size());
      out.nodes.push_back({coord[3 * i], coord[3 * i + 1]});
    }
    out.ring.assign(out.nodes.size(), -1);
    out.segment.assign(out.nodes.size(), -1);
    out.t.assign(out.nodes.size(), 0.0);
    // Nodes on the ring segments (with their end points), t by projection on the segment.
    for (const auto& [line, where] : line_of) {
      const auto [r, k] = where;
      const auto& ring = rings[r];
      const Eigen::Vector2d a = ring[k], b = ring[(k + 1) % ring.size()];
      gmsh::model::mesh::getNodes(tags, coord, param, 1, line, true, false);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        const int n = index.at(tags[i]);
        const Eigen::Vector2d p = out.nodes[n];
        double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        int seg = k;
        if ((p - a).norm() <= 1e-12 * (b - a).norm()) t = 0.0;
        if ((p - b).norm() <= 1e-12 * (b - a).norm()) t = 0.0, seg = static_cast<int>((k + 1) % ring.size());
        out.ring[n] = r;
        out.segment[n] = seg;
        out.t[n] = t;
      }
    }
    std::vector<std::size_t> element_tags, element_nodes;
    gmsh::model::mesh::getElementsByType(2, element_tags, element_nodes);
    if (!element_tags.empty())
      throw NumericalError("the quad mesher left " + std::to_string(element_tags.size()) + " triangles");
    gmsh::model::mesh::getElementsByType(3, element_tags, element_nodes);
    for (std::size_t e = 0; e < element_tags.size(); ++e) {
      std::array<int, 4> q;
      for (int j = 0; j < 4; ++j) q[j] = index.at(element_nodes[4 * e + j]);
      double area2 = 0.0;
      for (int j = 0; j < 4; ++j) {
        const Eigen::Vector2d &p = out.nodes[q[j]], &s = out.nodes[q[(j + 1) % 4]];
        area2 += p.x() * s.y() - p.y() * s.x();
      }
      if (area2 < 0.0) std::reverse(q.begin() + 1, q.end());
      out.quads.push_back(q);
    }
  } catch (const NumericalError&) {
    throw;
  } catch (const std::exception& e) {
    throw NumericalError(std::string("the quad mesher (Gmsh) failed: ") + e.what() + " (" + gmsh_last_error() + ")");
  } catch (...) {
    throw NumericalError("the quad mesher (Gmsh) failed: " + gmsh_last_error());
  }
  if (out.quads.empty()) throw NumericalError("the quad mesher (Gmsh) made no quadrilaterals");
  return out;
}

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
  // The mesher keeps a core busy (here, or in its child) while this thread
  // waits: the pool's callers meanwhile leave it that core.
  const detail::LentCore lent;
#if defined(__SANITIZE_ADDRESS__)
  return quad_mesh_here(rings, size);
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
      m = quad_mesh_here(rings, size);
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
