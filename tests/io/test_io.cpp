// Tests of the I/O module: atomic file writes, .vtu and .pvd writers.
#include <doctest/doctest.h>
#include <sys/resource.h>
#include <unistd.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.h"
#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "toolkit/io/vtu_writer.h"

namespace fs = std::filesystem;
using toolkit::IoError;
using namespace toolkit::io;

namespace {

/// A fresh temporary directory, removed with everything in it on destruction.
struct TempDir {
  fs::path path;
  TempDir() {
    static std::atomic<int> counter{0};
    path = fs::temp_directory_path() /
           ("tspline_test_io_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

std::vector<std::string> entries_of(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_plain(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out << content;
}

/// quad 0-1-2-3, pentagon 1-4-5-6-2, line 3-7, vertex 7.
VtuMesh sample_mesh() {
  VtuMesh m;
  m.points = {{0.0, 0.0}, {1.0, 0.0},  {1.0, 1.0},       {0.0, 1.0},
              {2.0, 0.0}, {2.5, 0.75}, {1.5, 1.0 / 3.0}, {-0.5, 1.5e-300}};
  m.cells = {{0, 1, 2, 3}, {1, 4, 5, 6, 2}, {3, 7}, {7}};
  const std::size_t n = m.points.size();
  std::vector<double> px(n), py(n);
  std::vector<int> pid(n);
  std::vector<Eigen::Vector2d> vel(n);
  for (std::size_t i = 0; i < n; ++i) {
    px[i] = m.points[i].x() * 3.25 - 0.1;
    py[i] = 1.0 / (static_cast<double>(i) + 3.0);
    pid[i] = static_cast<int>(i) * 7 - 20;
    vel[i] = Eigen::Vector2d(0.5 * static_cast<double>(i), -1.0e-7 * static_cast<double>(i * i));
  }
  m.point_scalars = {{"px", px}, {"py", py}};
  m.point_ints = {{"id", pid}};
  m.point_vectors = {{"velocity", vel}};
  m.cell_scalars = {{"quality", {0.9, 0.123456789012345678, -4.0, 1e300}}};
  m.cell_ints = {{"kind", {4, 5, 2, -2147483647 - 1}}, {"region", {1, 1, 2, 3}}};
  return m;
}

vtkSmartPointer<vtkUnstructuredGrid> read_vtu(const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  REQUIRE(reader->GetErrorCode() == vtkErrorCode::NoError);
  vtkSmartPointer<vtkUnstructuredGrid> grid = reader->GetOutput();
  REQUIRE(grid != nullptr);
  return grid;
}

void check_same(const VtuMesh& m, vtkUnstructuredGrid* g) {
  REQUIRE(g->GetNumberOfPoints() == static_cast<vtkIdType>(m.points.size()));
  REQUIRE(g->GetNumberOfCells() == static_cast<vtkIdType>(m.cells.size()));
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    double p[3];
    g->GetPoint(static_cast<vtkIdType>(i), p);
    CHECK(p[0] == m.points[i].x());
    CHECK(p[1] == m.points[i].y());
    CHECK(p[2] == 0.0);
  }
  for (std::size_t c = 0; c < m.cells.size(); ++c) {
    const auto& cell = m.cells[c];
    int expected_type = VTK_POLYGON;
    if (cell.size() == 1) expected_type = VTK_VERTEX;
    if (cell.size() == 2) expected_type = VTK_LINE;
    if (cell.size() == 4 && !m.quads_as_polygons) expected_type = VTK_QUAD;
    CHECK(g->GetCellType(static_cast<vtkIdType>(c)) == expected_type);
    vtkNew<vtkIdList> ids;
    g->GetCellPoints(static_cast<vtkIdType>(c), ids);
    REQUIRE(ids->GetNumberOfIds() == static_cast<vtkIdType>(cell.size()));
    for (std::size_t k = 0; k < cell.size(); ++k) CHECK(ids->GetId(static_cast<vtkIdType>(k)) == cell[k]);
  }
  auto check_doubles = [](vtkDataArray* a, const std::vector<double>& v) {
    REQUIRE(a != nullptr);
    REQUIRE(vtkDoubleArray::SafeDownCast(a) != nullptr);
    REQUIRE(a->GetNumberOfComponents() == 1);
    REQUIRE(a->GetNumberOfTuples() == static_cast<vtkIdType>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) CHECK(a->GetComponent(static_cast<vtkIdType>(i), 0) == v[i]);
  };
  auto check_ints = [](vtkDataArray* a, const std::vector<int>& v) {
    REQUIRE(a != nullptr);
    auto* ia = vtkIntArray::SafeDownCast(a);
    REQUIRE(ia != nullptr);
    REQUIRE(ia->GetNumberOfComponents() == 1);
    REQUIRE(ia->GetNumberOfTuples() == static_cast<vtkIdType>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) CHECK(ia->GetValue(static_cast<vtkIdType>(i)) == v[i]);
  };
  vtkPointData* pd = g->GetPointData();
  vtkCellData* cd = g->GetCellData();
  CHECK(pd->GetNumberOfArrays() ==
        static_cast<int>(m.point_scalars.size() + m.point_ints.size() + m.point_vectors.size()));
  CHECK(cd->GetNumberOfArrays() == static_cast<int>(m.cell_scalars.size() + m.cell_ints.size()));
  for (const auto& [name, v] : m.point_scalars) check_doubles(pd->GetArray(name.c_str()), v);
  for (const auto& [name, v] : m.point_ints) check_ints(pd->GetArray(name.c_str()), v);
  for (const auto& [name, v] : m.cell_scalars) check_doubles(cd->GetArray(name.c_str()), v);
  for (const auto& [name, v] : m.cell_ints) check_ints(cd->GetArray(name.c_str()), v);
  for (const auto& [name, v] : m.point_vectors) {
    vtkDataArray* a = pd->GetArray(name.c_str());
    REQUIRE(a != nullptr);
    REQUIRE(vtkDoubleArray::SafeDownCast(a) != nullptr);
    REQUIRE(a->GetNumberOfComponents() == 3);
    REQUIRE(a->GetNumberOfTuples() == static_cast<vtkIdType>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) {
      const auto t = static_cast<vtkIdType>(i);
      CHECK(a->GetComponent(t, 0) == v[i].x());
      CHECK(a->GetComponent(t, 1) == v[i].y());
      CHECK(a->GetComponent(t, 2) == 0.0);
    }
  }
}

template <class F>
void check_invalid_and_nothing_written(const TempDir& dir, F&& mutate, const std::string& needle) {
  VtuMesh m = sample_mesh();
  mutate(m);
  const std::string target = dir / "bad.vtu";
  std::string message;
  try {
    write_vtu(target, m);
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  CHECK_MESSAGE(message.find(needle) != std::string::npos, "message: '", message, "' lacks '", needle, "'");
  CHECK(entries_of(dir.path).empty());
}

}  // namespace

TEST_SUITE("io") {
  TEST_CASE("write_vtu round trip: quad/pentagon/line/vertex with all array kinds") {
    TempDir dir;
    for (const bool quads_as_polygons : {true, false}) {
      CAPTURE(quads_as_polygons);
      VtuMesh m = sample_mesh();
      m.quads_as_polygons = quads_as_polygons;
      const std::string path = dir / "mesh.vtu";
      write_vtu(path, m);
      CHECK(entries_of(dir.path) == std::vector<std::string>{"mesh.vtu"});
      check_same(m, read_vtu(path));

      // Binary appended, raw (not base64), LZ4-compressed by default.
      const std::string text = read_all(path);
      CHECK(text.find("type=\"UnstructuredGrid\"") != std::string::npos);
      CHECK(text.find("compressor=\"vtkLZ4DataCompressor\"") != std::string::npos);
      CHECK(text.find("format=\"appended\"") != std::string::npos);
      CHECK(text.find("<AppendedData encoding=\"raw\">") != std::string::npos);
      CHECK(text.find("format=\"ascii\"") == std::string::npos);
      // Connectivity and offsets in 32 bits (the writer checks that they fit).
      CHECK(text.find("type=\"Int32\" Name=\"connectivity\"") != std::string::npos);
      CHECK(text.find("type=\"Int32\" Name=\"offsets\"") != std::string::npos);
    }
  }

  TEST_CASE("write_vtu: each compression named in the file and read back bit for bit") {
    TempDir dir;
    const VtuMesh m = sample_mesh();
    const std::vector<std::pair<VtuCompression, std::string>> cases = {
        {VtuCompression::LZ4, "vtkLZ4DataCompressor"}, {VtuCompression::Zlib, "vtkZLibDataCompressor"}};
    for (const auto& [compression, compressor] : cases) {
      CAPTURE(compressor);
      const std::string path = dir / "mesh.vtu";
      write_vtu(path, m, compression);
      check_same(m, read_vtu(path));
      CHECK(read_all(path).find("compressor=\"" + compressor + "\"") != std::string::npos);
    }
    const std::string path = dir / "raw.vtu";
    write_vtu(path, m, VtuCompression::None);
    check_same(m, read_vtu(path));
    CHECK(read_all(path).find("compressor=") == std::string::npos);
    // The names of the command-line option and of the Python keyword.
    for (const VtuCompression c : {VtuCompression::LZ4, VtuCompression::Zlib, VtuCompression::None})
      CHECK(parse_vtu_compression(vtu_compression_name(c)) == c);
    CHECK(vtu_compression_name(VtuCompression::LZ4) == "lz4");
    CHECK_THROWS_WITH_AS(parse_vtu_compression("gzip"), "unknown .vtu compression 'gzip' (lz4, zlib or none)",
                         toolkit::InputError);
  }

  TEST_CASE("write_vtu: arrays of many zlib blocks (libdeflate), read back bit for bit through zlib") {
    // 40,000 points: every array spans several of VTK's 32 KiB blocks. VTK's
    // reader inflates them with zlib (vtkZLibDataCompressor), so a stream that
    // is not zlib's format, or a block lost, fails here. LZ4's blocks alike.
    TempDir dir;
    VtuMesh m;
    const std::size_t n = 40000;
    std::vector<double> noise(n), ramp(n);
    std::vector<int> ids(n);
    std::uint64_t state = 88172645463325252ull;  // xorshift64: incompressible low bits
    for (std::size_t i = 0; i < n; ++i) {
      state ^= state << 13, state ^= state >> 7, state ^= state << 17;
      noise[i] = static_cast<double>(state >> 11) * 0x1.0p-53;
      ramp[i] = 0.25 * static_cast<double>(i);
      ids[i] = static_cast<int>(i);
      m.points.emplace_back(std::sin(1e-3 * static_cast<double>(i)), noise[i]);
      m.cells.push_back({static_cast<int>(i)});
    }
    m.point_scalars = {{"noise", noise}, {"ramp", ramp}};
    m.point_ints = {{"id", ids}};
    const std::string path = dir / "big.vtu";
    write_vtu(path, m, VtuCompression::Zlib);
    check_same(m, read_vtu(path));
    const std::string text = read_all(path);
    CHECK(text.find("compressor=\"vtkZLibDataCompressor\"") != std::string::npos);
    // Compressed: points (24 B), two doubles and two ints (ids, and the cells'
    // connectivity and offsets) per point raw; the ramp, the ids, the z = 0
    // and the cells compress to little, the noise and the points' x and y not.
    const std::size_t raw = n * (24 + 8 + 8 + 4 + 4 + 4 + 1);
    CHECK(text.size() < raw * 3 / 4);
    const std::string lz4_path = dir / "big_lz4.vtu";
    write_vtu(lz4_path, m);
    check_same(m, read_vtu(lz4_path));
    const std::string lz4_text = read_all(lz4_path);
    CHECK(lz4_text.find("compressor=\"vtkLZ4DataCompressor\"") != std::string::npos);
    // LZ4 packs the repeated bytes (z = 0, the cells' types) but finds fewer
    // of zlib's short matches: between zlib's file and the raw arrays.
    MESSAGE("raw arrays ", raw, " B, zlib file ", text.size(), " B, LZ4 file ", lz4_text.size(), " B");
    CHECK(lz4_text.size() > text.size());
    CHECK(lz4_text.size() < raw * 9 / 10);
  }

  TEST_CASE("first use of VTK on two threads at once, in new processes: both files written, nothing leaked") {
    // VTK makes its object-factory registry on first use without a lock; two
    // threads could both make one and leak one (80 bytes, caught by
    // LeakSanitizer in the sanitizer build: the helper's exit status is then
    // non-zero). Two threads each writing one .vtu in a new process leaked in
    // about half of the runs before toolkit_io set VTK up once
    // (vtk_threads.h); 20 runs.
    TempDir dir;
    for (int run = 0; run < 20; ++run) {
      CAPTURE(run);
      const test_support::AppRun r =
          test_support::run_program(VTK_TWO_LANES_PATH, test_support::quoted(dir.path), dir.path);
      CAPTURE(r.err);
      REQUIRE(r.exit_code == 0);
      for (const char* name : {"lane0.vtu", "lane1.vtu"}) {
        REQUIRE(fs::exists(dir / name));
        CHECK(read_vtu(dir / name)->GetNumberOfPoints() == 3);
        fs::remove(dir / name);
      }
    }
  }

  TEST_CASE("merge_vtu, write_vtu_parts and write_vtu_pieces: the parts as one mesh, the same file contents") {
    TempDir dir;
    // Three parts: the sample mesh, the same moved (an extra array that the
    // others lack is dropped), and a triangle.
    std::vector<VtuMesh> parts = {sample_mesh(), sample_mesh(), sample_mesh()};
    for (Eigen::Vector2d& p : parts[1].points) p += Eigen::Vector2d(10.0, -3.0);
    parts[1].point_scalars["only_here"] = std::vector<double>(parts[1].points.size(), 1.0);
    parts[2].points = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
    parts[2].cells = {{0, 1, 2}};
    for (auto& [name, v] : parts[2].point_scalars) v = {1.0, 2.0, 3.0};
    parts[2].point_ints["id"] = {7, 8, 9};
    parts[2].point_vectors["velocity"] = {{1, 2}, {3, 4}, {5, 6}};
    parts[2].cell_scalars["quality"] = {0.5};
    parts[2].cell_ints = {{"kind", {3}}, {"region", {9}}};
    const VtuMesh merged = merge_vtu(parts, "part");
    REQUIRE(merged.points.size() == 8 + 8 + 3);
    REQUIRE(merged.cells.size() == 4 + 4 + 1);
    CHECK(merged.cells[4] == std::vector<int>{8, 9, 10, 11});  // offset by the first part's 8 points
    CHECK(merged.cells[8] == std::vector<int>{16, 17, 18});
    CHECK(merged.points[9] == parts[1].points[1]);
    CHECK(merged.point_scalars.count("only_here") == 0);
    CHECK(merged.cell_ints.at("part") == std::vector<int>{0, 0, 0, 0, 1, 1, 1, 1, 2});
    CHECK(merged.cell_ints.at("region") == std::vector<int>{1, 1, 2, 3, 1, 1, 2, 3, 9});
    CHECK(merged.point_ints.at("id")[17] == 8);
    // The merged mesh written whole, the parts written without merging, and
    // the parts as pieces (one part per piece, its part index added): VTK
    // reads the same grid from all three.
    write_vtu(dir / "merged.vtu", merged);
    std::vector<VtuMesh> copy = parts;
    write_vtu_parts(dir / "parts.vtu", std::move(copy), "part");
    CHECK(copy.empty());
    CHECK(read_all(dir / "parts.vtu") == read_all(dir / "merged.vtu"));  // byte for byte
    int made = 0;
    write_vtu_pieces(dir / "pieces.vtu", 3, [&](int i) {
      ++made;
      VtuMesh piece = parts[static_cast<std::size_t>(i)];
      piece.point_scalars.erase("only_here");
      piece.cell_ints["part"] = std::vector<int>(piece.cells.size(), i);
      return piece;
    });
    CHECK(made == 3);
    const std::string text = read_all(dir / "pieces.vtu");
    std::size_t pieces = 0;
    for (std::size_t at = text.find("<Piece"); at != std::string::npos; at = text.find("<Piece", at + 1)) ++pieces;
    CHECK(pieces == 3);
    check_same(merged, read_vtu(dir / "pieces.vtu"));
    check_same(merged, read_vtu(dir / "parts.vtu"));
    // Pieces made of parts (piece 0: the first two, piece 1: the third), their
    // part indices counted from each piece's first part: the merged mesh again.
    write_vtu_part_pieces(dir / "part_pieces.vtu", 2, [&](int i) {
      VtuParts piece;
      piece.part_array = "part";
      piece.first_part = 2 * i;
      if (i == 0)
        piece.parts = {parts[0], parts[1]};
      else
        piece.parts = {parts[2]};
      return piece;
    });
    const vtkSmartPointer<vtkUnstructuredGrid> g = read_vtu(dir / "part_pieces.vtu");
    check_same(merged, g);  // (its `part` array: 0 0 0 0 1 1 1 1 2)
    // A piece that cannot be made: its error, and no file.
    CHECK_THROWS_WITH_AS(write_vtu_pieces(dir / "broken.vtu", 2,
                                          [&](int i) -> VtuMesh {
                                            if (i == 1) throw std::runtime_error("piece 1 failed");
                                            return parts[0];
                                          }),
                         "piece 1 failed", std::runtime_error);
    CHECK_FALSE(fs::exists(dir / "broken.vtu"));
    CHECK_THROWS_AS(write_vtu_pieces(dir / "none.vtu", 0, [&](int) { return parts[0]; }), std::invalid_argument);
  }

  TEST_CASE("write_vtu: empty mesh and mesh without arrays") {
    TempDir dir;
    VtuMesh empty;
    write_vtu(dir / "empty.vtu", empty);
    check_same(empty, read_vtu(dir / "empty.vtu"));

    VtuMesh bare;
    bare.points = {{0, 0}, {1, 0}, {0, 1}};
    bare.cells = {{0, 1, 2}};
    write_vtu(dir / "bare.vtu", bare);
    check_same(bare, read_vtu(dir / "bare.vtu"));
  }

  TEST_CASE("write_vtu overwrites an existing file entirely") {
    TempDir dir;
    const std::string path = dir / "mesh.vtu";
    write_plain(path, std::string(200000, 'x'));  // larger than the .vtu
    VtuMesh m = sample_mesh();
    write_vtu(path, m);
    const std::string text = read_all(path);
    CHECK(text.size() < 200000);
    CHECK(text.find("xxxxxxxx") == std::string::npos);
    check_same(m, read_vtu(path));
    CHECK(entries_of(dir.path) == std::vector<std::string>{"mesh.vtu"});
  }

  TEST_CASE("write_vtu validates input before writing anything") {
    TempDir dir;
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.point_scalars["px"].pop_back(); }, "'px'");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.point_ints["id"].push_back(1); }, "'id'");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.point_vectors["velocity"].clear(); }, "'velocity'");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.cell_scalars["quality"].push_back(0.0); },
                                      "'quality'");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.cell_ints["kind"].pop_back(); }, "'kind'");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.cells[1][2] = 8; }, "point 8");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.cells[0][0] = -1; }, "point -1");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.cells.push_back({}); }, "no points");
    check_invalid_and_nothing_written(dir, [](VtuMesh& m) { m.point_ints["px"] = std::vector<int>(8, 0); },
                                      "duplicate");

    // An existing file is left untouched by a rejected write.
    const std::string keep = dir / "keep.vtu";
    write_plain(keep, "old");
    VtuMesh m = sample_mesh();
    m.cell_ints["region"].push_back(5);
    CHECK_THROWS_AS(write_vtu(keep, m), std::invalid_argument);
    CHECK(read_all(keep) == "old");
    CHECK(entries_of(dir.path) == std::vector<std::string>{"keep.vtu"});
  }

  TEST_CASE("write_vtu into a missing directory or below a regular file throws IoError, leaves nothing") {
    TempDir dir;
    const std::string missing = dir / "no/such/dir/mesh.vtu";
    try {
      write_vtu(missing, sample_mesh());
      FAIL("no exception");
    } catch (const IoError& e) {
      const std::string msg = e.what();
      CHECK(msg.find(missing) != std::string::npos);
      CHECK(msg.find("No such file or directory") != std::string::npos);
      CHECK(msg.find('\n') == std::string::npos);
    }
    CHECK(entries_of(dir.path).empty());

    write_plain(dir / "file", "content");
    CHECK_THROWS_AS(write_vtu(dir / "file/mesh.vtu", sample_mesh()), IoError);
    CHECK_THROWS_AS(write_pvd(dir / "file/series.pvd", {}), IoError);
    CHECK(entries_of(dir.path) == std::vector<std::string>{"file"});
    CHECK(read_all(dir / "file") == "content");

    CHECK_THROWS_AS(write_vtu("/proc/tspline_test_io.vtu", sample_mesh()), IoError);
    CHECK_FALSE(fs::exists("/proc/tspline_test_io.vtu"));
  }

  TEST_CASE("write_vtu: a failing VTK writer (file size limit) throws IoError and leaves nothing") {
    // Simulates a full disk after the temporary was created: with RLIMIT_FSIZE
    // the writes of the VTK writer itself fail (EFBIG; SIGXFSZ is ignored).
    TempDir dir;
    const std::string path = dir / "big.vtu";
    write_plain(path, "previous");
    std::string message;
    {
      struct LimitGuard {
        rlimit old{};
        void (*old_handler)(int) = SIG_DFL;
        LimitGuard() {
          REQUIRE(::getrlimit(RLIMIT_FSIZE, &old) == 0);
          old_handler = std::signal(SIGXFSZ, SIG_IGN);
          rlimit lim = old;
          lim.rlim_cur = 300;
          REQUIRE(::setrlimit(RLIMIT_FSIZE, &lim) == 0);
        }
        ~LimitGuard() {
          ::setrlimit(RLIMIT_FSIZE, &old);
          std::signal(SIGXFSZ, old_handler);
        }
      } guard;
      try {
        write_vtu(path, sample_mesh());
      } catch (const IoError& e) {
        message = e.what();
      }
    }
    INFO("message: ", message);
    CHECK(message.rfind("cannot write '" + path + "': ", 0) == 0);
    CHECK(message.find('\n') == std::string::npos);
    CHECK(read_all(path) == "previous");
    CHECK(entries_of(dir.path) == std::vector<std::string>{"big.vtu"});
  }

  TEST_CASE("write_text_atomic: create, replace entirely, no temporaries left") {
    TempDir dir;
    const std::string path = dir / "a.txt";
    write_text_atomic(path, std::string(10000, 'a'));
    CHECK(read_all(path) == std::string(10000, 'a'));
    write_text_atomic(path, "short\n");
    CHECK(read_all(path) == "short\n");
    write_text_atomic(path, "");
    CHECK(read_all(path).empty());
    CHECK(entries_of(dir.path) == std::vector<std::string>{"a.txt"});

    // Relative path (no directory component) works as well.
    {
      struct CwdGuard {
        fs::path old = fs::current_path();
        ~CwdGuard() { fs::current_path(old); }
      } guard;
      fs::current_path(dir.path);
      write_text_atomic("rel.txt", "relative");
    }
    CHECK(read_all(dir / "rel.txt") == "relative");
  }

  TEST_CASE("write_text_atomic failures throw IoError naming the path") {
    TempDir dir;
    write_plain(dir / "plain", "x");
    for (const std::string& bad : {dir / "missing/a.txt", dir / "plain/a.txt", std::string("/proc/tspline_x.txt")}) {
      CAPTURE(bad);
      try {
        write_text_atomic(bad, "data");
        FAIL("no exception");
      } catch (const IoError& e) {
        CHECK(std::string(e.what()).find(bad) != std::string::npos);
      }
    }
    // Target is an existing directory: the rename fails, the temporary is removed.
    fs::create_directory(dir / "sub");
    CHECK_THROWS_AS(write_text_atomic(dir / "sub", "data"), IoError);
    CHECK(fs::is_directory(dir / "sub"));
    CHECK(entries_of(dir.path) == std::vector<std::string>{"plain", "sub"});
    CHECK(entries_of(dir.path / "sub").empty());
    // No file name at all.
    CHECK_THROWS_AS(write_text_atomic(dir / "sub/", "data"), IoError);
    CHECK(entries_of(dir.path / "sub").empty());
  }

  TEST_CASE("write_atomic: temporary lives next to the target and is removed when the writer throws") {
    TempDir dir;
    const std::string target = dir / "out.dat";
    write_plain(target, "previous");

    std::string seen_tmp;
    CHECK_THROWS_AS(write_atomic(target,
                                 [&](const std::string& tmp) {
                                   seen_tmp = tmp;
                                   write_plain(tmp, "partial");
                                   throw std::runtime_error("writer failed");
                                 }),
                    std::runtime_error);
    CHECK(fs::path(seen_tmp).parent_path() == dir.path);
    CHECK(fs::path(seen_tmp).filename().string().rfind(".out.dat.tmp.", 0) == 0);
    CHECK_FALSE(fs::exists(seen_tmp));
    CHECK(read_all(target) == "previous");
    CHECK(entries_of(dir.path) == std::vector<std::string>{"out.dat"});

    // Successful write: the temporary is renamed onto the target.
    write_atomic(target, [&](const std::string& tmp) {
      CHECK(tmp != seen_tmp);  // unique names
      write_plain(tmp, "new");
    });
    CHECK(read_all(target) == "new");
    CHECK(entries_of(dir.path) == std::vector<std::string>{"out.dat"});

    // A writer that deletes its temporary instead of producing it.
    CHECK_THROWS_AS(write_atomic(target, [](const std::string& tmp) { fs::remove(tmp); }), IoError);
    CHECK(read_all(target) == "new");
  }

  TEST_CASE("ensure_writable_directory") {
    TempDir dir;
    const std::string nested = dir / "a/b/c";
    ensure_writable_directory(nested);
    CHECK(fs::is_directory(nested));
    CHECK(entries_of(nested).empty());  // probe removed
    ensure_writable_directory(nested);  // existing directory is fine

    write_plain(dir / "regular", "x");
    try {
      ensure_writable_directory(dir / "regular");
      FAIL("no exception");
    } catch (const IoError& e) {
      CHECK(std::string(e.what()).find(dir / "regular") != std::string::npos);
    }
    CHECK_THROWS_AS(ensure_writable_directory(dir / "regular/sub"), IoError);
    CHECK(read_all(dir / "regular") == "x");
    CHECK_THROWS_AS(ensure_writable_directory("/proc/tspline_test_dir"), IoError);
    CHECK_THROWS_AS(ensure_writable_directory("/proc/self"), IoError);  // exists, not writable
  }

  TEST_CASE("write_pvd writes a collection and escapes file names") {
    TempDir dir;
    const std::string path = dir / "series.pvd";
    const std::vector<PvdEntry> entries = {
        {0.0, "step_0.vtu", 0},
        {0.1, "step \"1\" <a&b>'.vtu", 2},
        {1e-20, "sub/step_2.vtu", 0},
    };
    write_pvd(path, entries);
    const std::string text = read_all(path);
    CHECK(text.rfind("<?xml version=\"1.0\"?>", 0) == 0);
    CHECK(text.find("<VTKFile type=\"Collection\" version=\"0.1\"") != std::string::npos);
    CHECK(text.find("<Collection>") != std::string::npos);
    CHECK(text.find("</Collection>") != std::string::npos);
    CHECK(text.find("</VTKFile>") != std::string::npos);
    CHECK(text.find("<DataSet timestep=\"0\" part=\"0\" file=\"step_0.vtu\"/>") != std::string::npos);
    CHECK(text.find("<DataSet timestep=\"0.1\" part=\"2\" file=\"step &quot;1&quot; &lt;a&amp;b&gt;&apos;.vtu\"/>") !=
          std::string::npos);
    CHECK(text.find("<DataSet timestep=\"1e-20\" part=\"0\" file=\"sub/step_2.vtu\"/>") != std::string::npos);

    std::size_t count = 0;
    for (std::size_t pos = text.find("<DataSet "); pos != std::string::npos; pos = text.find("<DataSet ", pos + 1))
      ++count;
    CHECK(count == entries.size());

    // Overwrite with an empty collection.
    write_pvd(path, {});
    const std::string empty = read_all(path);
    CHECK(empty.find("<DataSet") == std::string::npos);
    CHECK(empty.find("</Collection>") != std::string::npos);
    CHECK(entries_of(dir.path) == std::vector<std::string>{"series.pvd"});

    CHECK_THROWS_AS(write_pvd(path, {{std::nan(""), "x.vtu", 0}}), std::invalid_argument);
    CHECK(read_all(path) == empty);
  }
}
