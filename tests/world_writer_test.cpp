// The writer: exact round trips, the original creator's format, extensions, atomic replace.
#include "src/world/world_writer.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <thread>

#include "src/base/atomic_file.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"
#include "tests/test_support.h"

namespace jello {
namespace {

bool sameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

void expectSameBits(const Vec3& a, const Vec3& b) {
  EXPECT_TRUE(sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z));
}

TEST(WorldWriter, RoundTripsEveryDoubleBitExactly) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> any(-2.0, 2.0);
  SceneSpec spec;
  spec.fieldResolution = 3;
  spec.sphere = Sphere{{0.1, 0.2, 0.3}, 0.4};
  World w = buildWorld(spec);
  w.dt = std::nextafter(1e-3, 1.0);
  w.mass = 1.0 / 3.0;
  w.kElastic = std::numeric_limits<double>::denorm_min();
  w.dCollision = std::numeric_limits<double>::max();
  // Extremes where the reader allows them: positions start within 100 m, forces are free.
  for (Vec3& x : w.positions) x = {any(rng), any(rng) * 1e-300, any(rng) * 10};
  for (Vec3& v : w.velocities) v = {any(rng) / 3, any(rng) / 7, -0.0};
  for (Vec3& f : w.field.forces) f = {any(rng) * 1e300, any(rng) * 1e-300, any(rng)};

  const World r = parseWorld(formatWorld(w), "roundtrip");
  EXPECT_TRUE(sameBits(r.dt, w.dt));
  EXPECT_TRUE(sameBits(r.mass, w.mass));
  EXPECT_TRUE(sameBits(r.kElastic, w.kElastic));
  EXPECT_TRUE(sameBits(r.dCollision, w.dCollision));
  ASSERT_EQ(r.positions.size(), w.positions.size());
  for (std::size_t p = 0; p < w.positions.size(); ++p) {
    expectSameBits(r.positions[p], w.positions[p]);
    expectSameBits(r.velocities[p], w.velocities[p]);
  }
  for (std::size_t i = 0; i < w.field.forces.size(); ++i) {
    expectSameBits(r.field.forces[i], w.field.forces[i]);
  }
  ASSERT_TRUE(r.sphere.has_value());
  expectSameBits(r.sphere->center, w.sphere->center);
  EXPECT_EQ(formatWorld(r), formatWorld(w));
}

TEST(WorldWriter, LegacyFormatOfTheDefaultSceneIsTheOriginalCreatorsFile) {
  const std::string expected = test::readFile(test::worldsDir() / "createWorld-default.w");
  EXPECT_EQ(formatWorld(buildWorld(SceneSpec{}), NumberFormat::Legacy), expected);
}

TEST(WorldWriter, ReproducesAReferenceWorldOnEveryLineButTheHandEditedOne) {
  // rotate.w is printed exactly as the original %lf writer would print it.
  const World w = test::loadWorld("rotate.w");
  EXPECT_EQ(formatWorld(w, NumberFormat::Legacy), test::readFile(test::worldsDir() / "rotate.w"));
}

TEST(WorldWriter, WritesNoExtensionBlockForAnOriginalScene) {
  const std::string text = formatWorld(test::loadWorld("jello.w"));
  EXPECT_EQ(text.find("cube"), std::string::npos);
  EXPECT_EQ(text.find("sphere"), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 7 + 27000 + 1024);
}

// The original course loader reads line 1 into a 10-byte buffer and knows Euler and RK4: every
// written file keeps line 1 to one of them, and any other integrator travels in the extension
// block, which that loader never reads (#16 item 11).
TEST(WorldWriter, LineOneAlwaysHoldsANameTheOriginalLoaderKnows) {
  for (IntegratorKind kind : allIntegrators()) {
    World w = test::loadWorld("jello.w");
    w.integrator = kind;
    for (NumberFormat format : {NumberFormat::Exact, NumberFormat::Legacy}) {
      const std::string text = formatWorld(w, format);
      const std::string first = text.substr(0, text.find('\n'));
      EXPECT_TRUE(first == "RK4" || first == "Euler") << first;
      EXPECT_LT(first.size(), 10u);
      const bool original = kind == IntegratorKind::Euler || kind == IntegratorKind::RK4;
      EXPECT_EQ(text.find("\nintegrator ") != std::string::npos, !original) << integratorName(kind);
      EXPECT_EQ(parseWorld(text, "w").integrator, kind) << integratorName(kind);
    }
  }
  // A file of the earlier layout, the integrator on line 1, still reads; the extension wins
  // over line 1 where both are given.
  World w = test::loadWorld("jello.w");
  std::string text = formatWorld(w);
  EXPECT_EQ(parseWorld("bdf2" + text.substr(3), "old").integrator, IntegratorKind::Bdf2);
  EXPECT_EQ(parseWorld(text + "integrator midpoint\n", "new").integrator, IntegratorKind::Midpoint);
  ReaderLimits lenient;
  lenient.acceptUnknownIntegrator = true;
  EXPECT_EQ(parseWorld(text + "integrator IPC\n", "ipc", lenient).unknownIntegrator, "IPC");
}

TEST(WorldWriter, ExtensionsRoundTrip) {
  SceneSpec spec;
  spec.cubeResolution = 5;
  spec.sphere = Sphere{{0.0, 0.0, -1.0}, 0.5};
  spec.plane.reset();
  spec.fieldResolution = 0;
  const World w = buildWorld(spec);
  const World r = parseWorld(formatWorld(w), "ext");
  EXPECT_EQ(r.cubeResolution, 5);
  EXPECT_EQ(r.positions.size(), 125u);
  ASSERT_TRUE(r.sphere.has_value());
  EXPECT_EQ(r.sphere->radius, 0.5);
  EXPECT_FALSE(r.plane.has_value());
  EXPECT_TRUE(r.field.empty());
}

TEST(AtomicFile, ReplacesTheFileAndLeavesNoTemporary) {
  test::TempDir dir;
  const auto path = dir.path() / "w.w";
  writeFileAtomically(path, "old");
  writeFileAtomically(path, "new");
  EXPECT_EQ(test::readFile(path), "new");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            1);
}

TEST(AtomicFile, FailsWithThePathWhenTheDirectoryIsMissing) {
  test::TempDir dir;
  const auto path = dir.path() / "missing" / "w.w";
  try {
    writeFileAtomically(path, "x");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, KeepsThePreviousFileWhenTheTargetCannotBeReplaced) {
  test::TempDir dir;
  const auto path = dir.path() / "w.w";
  writeFileAtomically(path, "previous");
  // A directory in the way of the rename: the write fails after the temporary was written.
  const auto blocked = dir.path() / "blocked";
  std::filesystem::create_directories(blocked / "inner");
  EXPECT_THROW(writeFileAtomically(blocked, "new"), std::runtime_error);
  EXPECT_EQ(test::readFile(path), "previous");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            2);  // w.w and blocked/, no temporary left behind
}

// Special targets (#16): a device, FIFO or pipe is written in place, never replaced by a
// regular file; a symbolic link is followed and its file replaced; permissions are kept.
TEST(AtomicFile, WritesIntoAFifoWithoutReplacingIt) {
  test::TempDir dir;
  const auto fifo = dir.path() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  // The reader never blocks: should the FIFO be replaced, it gives up after 5 s.
  std::string received;
  std::thread reader([&] {
    const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
    if (fd < 0) return;
    for (int waited = 0; waited < 500; ++waited) {
      char buf[64];
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n > 0) {
        received.append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 && !received.empty()) {
        break;  // the writer wrote and closed
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
    ::close(fd);
  });
  writeFileAtomically(fifo, "through the fifo");
  reader.join();
  EXPECT_EQ(received, "through the fifo");
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            1);
}

// Issue 41 (low): a FIFO with no process at its other end blocked forever, as an output (--stats,
// stability.json, a viewer frame) and as a world; a socket as an output was refused only after
// the run. Each is now refused, the FIFOs after a wait, and a writer that comes is read whole.
TEST(AtomicFile, AFifoWithNobodyAtItsOtherEndIsRefusedAfterAWaitAndASocketAtOnce) {
  test::TempDir dir;
  const auto fifo = dir.path() / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  jello::testing::fifoWaitSeconds = 0.3;
  struct Restore {
    ~Restore() { jello::testing::fifoWaitSeconds = kFifoWaitSeconds; }
  } restore;
  const auto start = std::chrono::steady_clock::now();
  try {
    writeFileAtomically(fifo, "nobody reads this");
    ADD_FAILURE() << "wrote into a FIFO nobody reads";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a FIFO that no process reads (waited 0.3 s)"),
              std::string::npos)
        << e.what();
  }
  try {
    (void)readWorld(fifo);
    ADD_FAILURE() << "read a world from a FIFO nobody writes";
  } catch (const WorldFileError& e) {
    EXPECT_NE(std::string(e.what()).find("a FIFO that no process writes"), std::string::npos)
        << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));

  jello::testing::fifoWaitSeconds = 5.0;
  const World sent = test::loadWorld("jello.w");
  std::thread writer([&] { std::ofstream(fifo) << formatWorld(sent); });
  const World got = readWorld(fifo);
  writer.join();
  EXPECT_EQ(got.positions.size(), sent.positions.size());
  EXPECT_EQ(got.kElastic, sent.kElastic);

  const auto socketPath = dir.path() / "sock";
  const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(s, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, socketPath.c_str(), sizeof address.sun_path - 1);
  ASSERT_EQ(::bind(s, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0)
      << std::strerror(errno);
  EXPECT_NE(outputProblem(socketPath).find("it is a socket"), std::string::npos);
  ::close(s);
}

TEST(AtomicFile, WritesIntoAPipeNamedLikeDevStdout) {
  test::TempDir dir;
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const auto link = dir.path() / "stdout";  // as /dev/stdout -> /proc/self/fd/1
  std::filesystem::create_symlink("/proc/self/fd/" + std::to_string(fds[1]), link);
  writeFileAtomically(link, "to the pipe");
  ::close(fds[1]);
  char buf[64] = {};
  const ssize_t n = ::read(fds[0], buf, sizeof buf);
  ::close(fds[0]);
  EXPECT_EQ(std::string(buf, n > 0 ? static_cast<std::size_t>(n) : 0), "to the pipe");
  EXPECT_TRUE(std::filesystem::is_symlink(link));
}

TEST(AtomicFile, WritesIntoADeviceNodeWithoutReplacingIt) {
  test::TempDir dir;
  const auto node = dir.path() / "null";  // a private /dev/null: major 1, minor 3
  if (::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "cannot make a device node here (" << std::strerror(errno) << ")";
  }
  writeFileAtomically(node, "discarded");
  EXPECT_TRUE(std::filesystem::is_character_file(node));
}

TEST(AtomicFile, ReplacesTheFileASymlinkNamesAndKeepsTheLink) {
  test::TempDir dir;
  const auto file = dir.path() / "real.w";
  const auto link = dir.path() / "link.w";
  writeFileAtomically(file, "old");
  std::filesystem::create_symlink("real.w", link);  // relative, as users make them
  writeFileAtomically(link, "new");
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(test::readFile(file), "new");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator{}),
            2);
}

TEST(AtomicFile, KeepsTheReplacedFilesPermissions) {
  test::TempDir dir;
  const auto path = dir.path() / "private.w";
  writeFileAtomically(path, "old");
  ASSERT_EQ(::chmod(path.c_str(), 0640), 0);
  writeFileAtomically(path, "new");
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
  EXPECT_EQ(test::readFile(path), "new");
}

// Ctrl-C (or SIGTERM, SIGHUP) in the middle of a write, in a program that leaves the signal at
// its default action: the program dies of it as before, but its temporary file is removed and
// the previous file stays whole. The signal is raised right after the temporary file exists.
TEST(AtomicFile, AFatalSignalDuringAWriteLeavesNoTemporaryFile) {
  for (const int signo : {SIGINT, SIGTERM, SIGHUP}) {
    test::TempDir dir;
    const auto path = dir.path() / "out.w";
    writeFileAtomically(path, "old");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      static int raised = 0;
      raised = signo;
      testing::afterTemporaryCreated = [] { std::raise(raised); };
      try {
        writeFileAtomically(path, std::string(1 << 20, 'x'));
      } catch (...) {
      }
      ::_exit(0);  // not reached: the signal kills the child
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "signal " << signo << ": status " << status;
    EXPECT_EQ(WTERMSIG(status), signo);
    EXPECT_EQ(test::readFile(path), "old");
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator{}),
              1)
        << "a temporary file was left after signal " << signo;
  }
  // Default actions are restored after the write.
  struct sigaction action {};
  ASSERT_EQ(::sigaction(SIGTERM, nullptr, &action), 0);
  EXPECT_EQ(action.sa_handler, SIG_DFL);
}

TEST(AtomicFile, RefusesADirectory) {
  test::TempDir dir;
  EXPECT_THROW(writeFileAtomically(dir.path(), "x"), std::runtime_error);
}

}  // namespace
}  // namespace jello
