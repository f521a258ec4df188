// Every writer goes through io::AtomicFile: a full disk, a missing folder, a file used as a folder,
// a failed write and a killed writer are typed errors (or a dead process) that leave the previous
// file byte for byte as it was and no temporary file behind. The failures are made so that they
// also bind for root: /dev/full, a regular file as the folder, and RLIMIT_FSIZE (a file-size limit
// applies to every user) in a forked child, which either sees EFBIG or, with SIGXFSZ caught, stops
// inside write(2) and is SIGKILLed there by the parent.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <simsr/eval/report.hpp>
#include <simsr/io/io.hpp>

namespace io_test_atomic_file {

namespace {

namespace fs = std::filesystem;
namespace io = simsr::io;
using simsr::WriteError;

/// A fresh, empty folder for one test case.
fs::path fresh_dir(const std::string& name) {
  const auto d = fs::path(SIMSR_TEST_TMP_DIR) / "atomic_file" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  REQUIRE_MESSAGE(in, "cannot read ", p.string());
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << bytes;
  REQUIRE(out.good());
}

std::set<std::string> entries(const fs::path& dir) {
  std::set<std::string> s;
  for (const auto& e : fs::directory_iterator(dir)) s.insert(e.path().filename().string());
  return s;
}

bool is_temporary(const std::string& name) { return name.size() > 10 && name.ends_with(".simsr-tmp") && name.front() == '.'; }

/// Runs `f`, which must throw WriteError naming `file` with errno `code` and `part` in its text.
void expect_write_error(const std::function<void()>& f, const fs::path& file, int code, const std::string& part) {
  bool thrown = false;
  try {
    f();
  } catch (const WriteError& e) {
    thrown = true;
    INFO(std::string(e.what()));
    CHECK(e.file() == file.string());
    CHECK(e.line() == 0);
    CHECK(e.error_code() == code);
    CHECK(std::string(e.what()).starts_with(file.string() + ": "));
    CHECK(std::string(e.what()).find(part) != std::string::npos);
  }
  CHECK_MESSAGE(thrown, "no WriteError writing ", file.string());
}

// ---- every writer kind, as one function of the target path ---------------------------------

simsr::TetMesh<double> two_tets() {
  simsr::TetMesh<double> m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
  m.T.resize(2, 4);
  m.T << 0, 1, 2, 3, 1, 2, 3, 4;
  return m;
}

io::NpyArray big_array(std::int64_t n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = double(i) * 0.5;
  return io::make_npy<double>({n}, v.data());
}

struct Writer {
  std::string kind, ext;
  std::function<void(const fs::path&)> write;
  bool by_extension = false;  ///< picks the format from the path: "/dev/full" itself has none
};

const std::vector<Writer>& writers() {
  static const std::vector<Writer> w = [] {
    const auto mesh = two_tets();
    simsr::TriMesh<double> surface;
    surface.V = mesh.V;
    surface.F.resize(2, 3);
    surface.F << 0, 1, 2, 1, 2, 3;
    const std::vector<simsr::eval::Series> series{{"Embedded", {1e-3, 2e-3, 1.5e-3}}, {"MLS", {2e-3, 1e-3, 3e-3}}};
    simsr::eval::ErrorStatistics st;
    st.count = 3;
    st.mean = st.median = 1e-3;
    st.std = 1e-4;
    st.max = 2e-3;
    st.min = 5e-4;
    return std::vector<Writer>{
        {"npy", ".npy", [](const fs::path& p) { io::write_npy(p, big_array(64)); }},
        {"npz stored", ".npz", [](const fs::path& p) { io::NpzArrays z; z["a"] = big_array(64); io::write_npz(p, z); }},
        {"npz deflate", ".npz",
         [](const fs::path& p) {
           io::NpzArrays z;
           z["a"] = big_array(64);
           io::write_npz(p, z, io::NpzCompression::Deflate);
         }},
        {"vtu", ".vtu", [mesh](const fs::path& p) { io::write_vtu(p, io::VtuGrid(mesh)); }},
        {"vtu ascii", ".vtu", [mesh](const fs::path& p) { io::write_vtu(p, io::VtuGrid(mesh), io::VtuFormat::Ascii); }},
        {"pvd", ".pvd", [](const fs::path& p) { io::write_pvd(p, {{0.0, "a/a_000000.vtu"}, {1.0, "a/a_000001.vtu"}}); }},
        {"obj (triangles)", ".obj", [surface](const fs::path& p) { io::write_obj(p, surface); }},
        {"obj (tets)", ".obj", [mesh](const fs::path& p) { io::write_obj_tets(p, mesh); }},
        {"msh 4.1", ".msh", [mesh](const fs::path& p) { io::write_msh(p, mesh); }},
        {"msh 2.2", ".msh", [mesh](const fs::path& p) { io::write_msh(p, mesh, io::MshVersion::v22); }},
        {"medit", ".mesh", [mesh](const fs::path& p) { io::write_medit(p, mesh); }},
        {"write_mesh", ".msh",
         [mesh](const fs::path& p) {
           io::MeshData<double> d;
           d.V = mesh.V;
           d.T = mesh.T;
           io::write_mesh(p, d);
         },
         true},
        {"csv (frames)", ".csv", [series](const fs::path& p) { simsr::eval::write_frame_csv(p, series); }},
        {"csv (statistics)", ".csv",
         [st](const fs::path& p) { simsr::eval::write_statistics_csv(p, {"Embedded", "MLS"}, {st, st}, 2.0); }},
        {"svg", ".svg", [series](const fs::path& p) { simsr::eval::write_svg_plot(p, series, "errors", "mean error"); }},
    };
  }();
  return w;
}

// ---- a child process under a file-size limit -----------------------------------------------

int g_report_fd = -1;

/// SIGXFSZ: the child is inside write(2) at the limit; it tells the parent and waits to be killed.
extern "C" void stop_in_write(int) {
  const char k = 'K';
  (void)!::write(g_report_fd, &k, 1);
  for (;;) ::pause();
}

/// What became of a child that ran `f` with RLIMIT_FSIZE = `limit` bytes: with `stop`, SIGXFSZ
/// stops it inside the write that reaches the limit and the parent SIGKILLs it there ("killed");
/// without, SIGXFSZ is ignored and write(2) fails with EFBIG: "WriteError <errno> <what>", or
/// "other <what>", or "none" when `f` returned.
std::string run_limited(std::size_t limit, bool stop, const std::function<void()>& f) {
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::close(fds[0]);
    g_report_fd = fds[1];
    std::string out;
    if (stop) {
      struct sigaction sa {};
      sa.sa_handler = stop_in_write;
      ::sigaction(SIGXFSZ, &sa, nullptr);
    } else {
      ::signal(SIGXFSZ, SIG_IGN);
    }
    struct rlimit rl {};
    ::getrlimit(RLIMIT_FSIZE, &rl);
    rl.rlim_cur = limit;
    if (::setrlimit(RLIMIT_FSIZE, &rl) != 0) {
      out = "setrlimit failed";
    } else {
      try {
        f();
        out = "none";
      } catch (const WriteError& e) {
        out = "WriteError " + std::to_string(e.error_code()) + " " + e.what();
      } catch (const std::exception& e) {
        out = std::string("other ") + e.what();
      }
    }
    (void)!::write(fds[1], out.data(), out.size());
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string got;
  char buf[4096];
  for (;;) {
    const ::ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got.append(buf, std::size_t(n));
    if (stop && got == "K") {
      ::kill(pid, SIGKILL);
      break;
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (stop && got == "K") {
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == SIGKILL);
    return "killed";
  }
  CHECK(WIFEXITED(status));
  return got;
}

}  // namespace

TEST_CASE("atomic file: a new file, a replaced file, no temporary left, modes as the user expects") {
  const auto dir = fresh_dir("basic");
  const auto p = dir / "a.txt";
  io::write_file_atomic(p, std::string_view("first"));
  CHECK(slurp(p) == "first");
  const mode_t mask = ::umask(0);
  ::umask(mask);
  CHECK((fs::status(p).permissions() & fs::perms::mask) == fs::perms(0666 & ~mask));
  ::chmod(p.c_str(), 0640);
  io::write_file_atomic(p, std::string_view("second, longer"));
  CHECK(slurp(p) == "second, longer");
  CHECK((fs::status(p).permissions() & fs::perms::mask) == fs::perms(0640));  // the replaced file's mode is kept
  const std::vector<std::byte> bytes{std::byte{0}, std::byte{255}, std::byte{10}};
  io::write_file_atomic(p, bytes);
  CHECK(slurp(p) == std::string("\0\xff\n", 3));
  CHECK(entries(dir) == std::set<std::string>{"a.txt"});

  SUBCASE("streaming: the temporary file lives in the same folder until commit") {
    io::AtomicFile f(p);
    REQUIRE(!f.temporary().empty());
    CHECK(f.temporary().parent_path() == dir);
    CHECK(is_temporary(f.temporary().filename().string()));
    CHECK(fs::exists(f.temporary()));
    f.write(std::string_view("third "));
    f.write(std::string_view("in two pieces"));
    CHECK(slurp(p) == std::string("\0\xff\n", 3));  // not yet
    f.commit();
    CHECK(f.temporary().empty());
    CHECK(slurp(p) == "third in two pieces");
    CHECK(entries(dir) == std::set<std::string>{"a.txt"});
    CHECK_THROWS_AS(f.write(std::string_view("x")), simsr::ArgumentError);
    CHECK_THROWS_AS(f.commit(), simsr::ArgumentError);
  }
  SUBCASE("abandoned (an exception before commit): the target is untouched, the temporary removed") {
    {
      io::AtomicFile f(p);
      f.write(std::string_view("never seen"));
    }
    CHECK(slurp(p) == std::string("\0\xff\n", 3));
    CHECK(entries(dir) == std::set<std::string>{"a.txt"});
  }
  SUBCASE("a file in the current folder (no folder in the path)") {
    const auto cwd = fs::current_path();
    fs::current_path(dir);
    io::write_file_atomic("b.txt", std::string_view("here"));
    fs::current_path(cwd);
    CHECK(slurp(dir / "b.txt") == "here");
    CHECK(entries(dir) == std::set<std::string>{"a.txt", "b.txt"});
  }
}

TEST_CASE("atomic file: the target kinds that are not a plain file") {
  const auto dir = fresh_dir("kinds");
  SUBCASE("a symbolic link: its target is replaced, the link kept") {
    spit(dir / "real.txt", "old");
    fs::create_symlink("real.txt", dir / "link.txt");
    io::write_file_atomic(dir / "link.txt", std::string_view("new"));
    CHECK(fs::is_symlink(dir / "link.txt"));
    CHECK(slurp(dir / "real.txt") == "new");
    CHECK(entries(dir) == std::set<std::string>{"link.txt", "real.txt"});
  }
  SUBCASE("a folder is an error") {
    fs::create_directory(dir / "sub");
    expect_write_error([&] { io::write_file_atomic(dir / "sub", std::string_view("x")); }, dir / "sub", EISDIR, "is a folder");
    CHECK(fs::is_directory(dir / "sub"));
    CHECK(fs::is_empty(dir / "sub"));
  }
  SUBCASE("/dev/null is written in place (and stays a device)") {
    io::write_file_atomic("/dev/null", std::string_view("discarded"));
    CHECK(fs::is_character_file("/dev/null"));
  }
  SUBCASE("a FIFO is written in place, in order") {
    const auto fifo = dir / "pipe";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    const int rd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // a reader, so the writer's open does not block
    REQUIRE(rd >= 0);
    io::write_file_atomic(fifo, std::string_view("through the pipe"));
    char buf[64] = {};
    const ::ssize_t n = ::read(rd, buf, sizeof buf);
    ::close(rd);
    CHECK(std::string(buf, std::size_t(std::max<::ssize_t>(n, 0))) == "through the pipe");
    CHECK(fs::is_fifo(fifo));
    CHECK(entries(dir) == std::set<std::string>{"pipe"});
  }
  SUBCASE("/dev/full: ENOSPC, and the device is left alone") {
    expect_write_error([] { io::write_file_atomic("/dev/full", std::string_view("x")); }, "/dev/full", ENOSPC, "No space left on device");
    CHECK(fs::is_character_file("/dev/full"));
  }
}

TEST_CASE("every writer: /dev/full, a missing folder and a file used as a folder are WriteErrors naming the file") {
  const auto dir = fresh_dir("errors");
  spit(dir / "plain", "a regular file, not a folder");
  for (const auto& w : writers()) {
    CAPTURE(w.kind);
    if (!w.by_extension) expect_write_error([&] { w.write("/dev/full"); }, "/dev/full", ENOSPC, "No space left on device");
    const auto full = dir / ("full" + w.ext);  // a link to /dev/full with the writer's extension
    fs::create_symlink("/dev/full", full);
    expect_write_error([&] { w.write(full); }, full, ENOSPC, "No space left on device");
    fs::remove(full);
    CHECK(fs::is_character_file("/dev/full"));
    const auto missing = dir / "missing" / ("out" + w.ext);
    expect_write_error([&] { w.write(missing); }, missing, ENOENT, "No such file or directory");
    CHECK(!fs::exists(dir / "missing"));
    const auto under_file = dir / "plain" / ("out" + w.ext);  // fails for root too
    expect_write_error([&] { w.write(under_file); }, under_file, ENOTDIR, "Not a directory");
    CHECK(slurp(dir / "plain") == "a regular file, not a folder");
    CHECK(entries(dir) == std::set<std::string>{"plain"});
    if (!w.by_extension) w.write("/dev/null");  // a special file that takes anything: in place, no error
  }
}

TEST_CASE("every writer: a write that fails midway (file-size limit, EFBIG) leaves the previous file and no temporary") {
  const auto dir = fresh_dir("efbig");
  for (const auto& w : writers()) {
    CAPTURE(w.kind);
    const auto p = dir / ("out" + w.ext);
    w.write(p);  // the previous file, written without a limit
    const std::string before = slurp(p);
    REQUIRE(before.size() > 16);
    const std::string got = run_limited(16, false, [&] { w.write(p); });
    CHECK(got.starts_with("WriteError " + std::to_string(EFBIG) + " " + p.string() + ": write failed: File too large"));
    CHECK(slurp(p) == before);
    CHECK(entries(dir) == std::set<std::string>{p.filename().string()});
    fs::remove(p);
  }
}

TEST_CASE("every writer: killed inside write(2) (SIGKILL) leaves the previous file byte-identical and readable") {
  const auto dir = fresh_dir("killed");
  for (const auto& w : writers()) {
    CAPTURE(w.kind);
    const auto p = dir / ("out" + w.ext);
    w.write(p);
    const std::string before = slurp(p);
    REQUIRE(before.size() > 16);
    CHECK(run_limited(16, true, [&] { w.write(p); }) == "killed");
    CHECK(slurp(p) == before);
    // The killed writer could not remove its temporary file: exactly one, hidden, holding the
    // 16 bytes written before the kill.
    std::vector<std::string> temps;
    for (const auto& name : entries(dir))
      if (name != p.filename().string()) temps.push_back(name);
    REQUIRE(temps.size() == 1);
    CHECK(is_temporary(temps[0]));
    std::string prefix = ".";  // (built by appends: GCC 12 warns falsely on "." + std::string)
    prefix += p.filename().string();
    prefix += '.';
    CHECK(temps[0].starts_with(prefix));
    CHECK(fs::file_size(dir / temps[0]) == 16);
    fs::remove(dir / temps[0]);
    fs::remove(p);
  }
  SUBCASE("a large .npy killed after 1 MiB reads back as the old array; the next write succeeds") {
    const auto p = dir / "frames.npy";
    const auto old_array = big_array(1000);
    io::write_npy(p, old_array);
    const std::string before = slurp(p);
    CHECK(run_limited(std::size_t(1) << 20, true, [&] { io::write_npy(p, big_array(std::int64_t(1) << 20)); }) == "killed");
    CHECK(slurp(p) == before);
    const auto back = io::read_npy(p);
    CHECK(back.shape == old_array.shape);
    CHECK(back.bytes == old_array.bytes);
    std::size_t temps = 0;
    for (const auto& name : entries(dir)) temps += is_temporary(name);
    CHECK(temps == 1);
    io::write_npy(p, big_array(2000));  // a leftover temporary does not stand in the way
    CHECK(io::read_npy(p).shape == std::vector<std::int64_t>{2000});
  }
}

TEST_CASE("PvdWriter: a series whose folder cannot be made is a WriteError; each frame and the .pvd are atomic") {
  const auto dir = fresh_dir("pvd");
  spit(dir / "plain", "x");
  const auto bad = dir / "plain" / "series.pvd";
  bool thrown = false;
  try {
    io::PvdWriter w(bad);
  } catch (const WriteError& e) {
    thrown = true;
    CHECK(e.file() == (dir / "plain" / "series").string());
    CHECK(e.error_code() != 0);
  }
  CHECK(thrown);
  io::PvdWriter w(dir / "series.pvd");
  w.add(0.0, io::VtuGrid(two_tets()));
  w.add(1.0, io::VtuGrid(two_tets()));
  CHECK(entries(dir) == std::set<std::string>{"plain", "series", "series.pvd"});
  CHECK(entries(dir / "series") == std::set<std::string>{"series_000000.vtu", "series_000001.vtu"});
}

TEST_CASE("TetGen: each of .node/.ele/.face is written atomically") {
  const auto dir = fresh_dir("tetgen");
  spit(dir / "plain", "x");
  const auto mesh = two_tets();
  expect_write_error([&] { io::write_tetgen(dir / "missing" / "cube", mesh); }, dir / "missing" / "cube.node", ENOENT, "No such file");
  expect_write_error([&] { io::write_tetgen(dir / "plain" / "cube", mesh); }, dir / "plain" / "cube.node", ENOTDIR, "Not a directory");
  io::write_tetgen(dir / "cube", mesh);
  const std::string node = slurp(dir / "cube.node"), ele = slurp(dir / "cube.ele");
  const std::string got = run_limited(16, false, [&] { io::write_tetgen(dir / "cube", mesh); });
  CHECK(got.starts_with("WriteError " + std::to_string(EFBIG) + " " + (dir / "cube.node").string()));
  CHECK(slurp(dir / "cube.node") == node);
  CHECK(slurp(dir / "cube.ele") == ele);
  CHECK(entries(dir) == std::set<std::string>{"cube.ele", "cube.node", "plain"});
}

TEST_CASE("an unwritable folder and a read-only file: WriteError (EACCES) for a user; root may write both") {
  const auto dir = fresh_dir("permissions");
  fs::create_directory(dir / "readonly");
  ::chmod((dir / "readonly").c_str(), 0555);
  spit(dir / "locked.txt", "kept");
  ::chmod((dir / "locked.txt").c_str(), 0444);
  const auto in_readonly = dir / "readonly" / "out.txt";
  if (::geteuid() != 0) {
    expect_write_error([&] { io::write_file_atomic(in_readonly, std::string_view("x")); }, in_readonly, EACCES, "Permission denied");
    expect_write_error([&] { io::write_file_atomic(dir / "locked.txt", std::string_view("x")); }, dir / "locked.txt", EACCES,
                       "refusing to replace a file that is not writable");
    CHECK(fs::is_empty(dir / "readonly"));
    CHECK(slurp(dir / "locked.txt") == "kept");
  } else {  // permissions do not bind root: the writes succeed, atomically as ever
    io::write_file_atomic(in_readonly, std::string_view("x"));
    io::write_file_atomic(dir / "locked.txt", std::string_view("x"));
    CHECK(entries(dir / "readonly") == std::set<std::string>{"out.txt"});
    CHECK(slurp(dir / "locked.txt") == "x");
  }
  CHECK(entries(dir) == std::set<std::string>{"locked.txt", "readonly"});
  ::chmod((dir / "readonly").c_str(), 0755);
}

}  // namespace io_test_atomic_file
