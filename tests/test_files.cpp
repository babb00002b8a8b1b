// Files as the command line meets them (issue 11, items 7, 8, 9 and 11; docs/interface.md, "Files"): outputs
// that are devices, FIFOs, symbolic links, folders, sockets or standard output; interruption by SIGINT and
// SIGTERM; work that cannot be done (a configuration without end, more trials than can run, a record larger
// than the disk); an empty configuration, a record with a byte order mark or unprintable bytes; a demo folder
// that is a file or read-only. Each test runs the gyrocal executable as a user would.
//
// No test touches anything outside its own folder: the character device is a pseudo-terminal the test opens
// itself (never /dev/null, which the code before this fix would have replaced by a file when run as root),
// and a test that could write without end runs with a limit on the file size.
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "support/cli_run.hpp"

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

using test::slurp;

/// How a run of the CLI ended: its exit status, or the signal that ended it.
struct Outcome {
  int status = -1;  ///< exit status, or -1 when a signal ended it
  int signal = 0;   ///< the signal that ended it, or 0
  std::string out, err;
};

Outcome decode(int raw) {
  Outcome o;
  if (WIFEXITED(raw)) o.status = WEXITSTATUS(raw);
  if (WIFSIGNALED(raw)) o.signal = WTERMSIG(raw);
  return o;
}

using test::short_test_toml;

class Files : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("gyrocal-files-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
            "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    work_ = dir_ / "work";
    fs::create_directories(work_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(work_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }

  /// Starts the CLI with `args` in the folder work_ (its current directory), standard input from
  /// /dev/null, standard output to `out_fd` (or the file dir_/stdout.txt when -1), standard error to
  /// dir_/stderr.txt, every signal at its default action, and `in_child` run just before exec (limits).
  pid_t spawn(const std::vector<std::string>& args, int out_fd = -1,
              const std::function<void()>& in_child = {}) const {
    std::vector<std::string> all{GYROCAL_CLI};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string out = (dir_ / "stdout.txt").string(), err = (dir_ / "stderr.txt").string();
    const std::string cwd = work_.string();
    const pid_t pid = ::fork();
    if (pid == 0) {
      // A test runner may ignore or block signals; the CLI must meet them as a shell would give them.
      for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) ::signal(s, SIG_DFL);
      sigset_t none;
      sigemptyset(&none);
      ::sigprocmask(SIG_SETMASK, &none, nullptr);
      if (::chdir(cwd.c_str()) != 0) ::_exit(126);
      const int in = ::open("/dev/null", O_RDONLY);
      const int o = out_fd >= 0 ? out_fd : ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (in < 0 || o < 0 || e < 0) ::_exit(126);
      ::dup2(in, 0);
      ::dup2(o, 1);
      ::dup2(e, 2);
      if (in_child) in_child();
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    return pid;
  }

  /// Waits for a spawned CLI and collects what it wrote (to files).
  Outcome finish(pid_t pid) const {
    int raw = 0;
    ::waitpid(pid, &raw, 0);
    Outcome o = decode(raw);
    o.out = slurp(dir_ / "stdout.txt");
    o.err = slurp(dir_ / "stderr.txt");
    return o;
  }

  Outcome run(const std::vector<std::string>& args, const std::function<void()>& in_child = {}) const {
    return finish(spawn(args, -1, in_child));
  }

  /// Runs the CLI while reading `fd` (a FIFO's or a pseudo-terminal's reading end, non-blocking) until it
  /// has ended and nothing is left: the bytes it delivered there.
  std::string run_reading(const std::vector<std::string>& args, int fd, Outcome& outcome) const {
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    const pid_t pid = spawn(args);
    std::string got;
    char buffer[1 << 16];
    bool ended = false;
    int raw = 0;
    for (;;) {
      pollfd p{fd, POLLIN, 0};
      ::poll(&p, 1, ended ? 0 : 50);
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n > 0) {
        got.append(buffer, static_cast<std::size_t>(n));
        continue;
      }
      if (ended) break;  // ended, and nothing more to read (EOF, EAGAIN or EIO)
      ended = ::waitpid(pid, &raw, WNOHANG) == pid;
    }
    outcome = decode(raw);
    outcome.out = slurp(dir_ / "stdout.txt");
    outcome.err = slurp(dir_ / "stderr.txt");
    return got;
  }

  fs::path path(const std::string& name) const { return work_ / name; }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
  }
  /// Entries of work_ besides the given ones (temporaries, half-written outputs), hidden ones included.
  std::vector<std::string> others(std::initializer_list<std::string> expected, fs::path folder = {}) const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(folder.empty() ? work_ : folder)) {
      const std::string n = e.path().filename().string();
      if (std::find(expected.begin(), expected.end(), n) == expected.end()) out.push_back(n);
    }
    return out;
  }

  fs::path dir_, work_;
};

bool is_character_device(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

// ---- Item 7: devices, FIFOs, symbolic links, folders, sockets, standard output ---------------------------

TEST_F(Files, ACharacterDeviceIsWrittenThroughAndStaysADevice) {
  // A pseudo-terminal in raw mode: a character device whose bytes the test reads back unchanged.
  int master = -1, slave = -1;
  char name[256] = {};
  ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0) << std::strerror(errno);
  ::fcntl(master, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave, F_SETFD, FD_CLOEXEC);
  termios raw_mode{};
  ::tcgetattr(slave, &raw_mode);
  ::cfmakeraw(&raw_mode);
  ::tcsetattr(slave, TCSANOW, &raw_mode);
  ASSERT_TRUE(is_character_device(name));

  const Outcome expected = run({"init", "-"});
  ASSERT_EQ(expected.status, 0) << expected.err;
  // No --force: a device is not a file to overwrite, nothing is replaced.
  Outcome o;
  const std::string got = run_reading({"init", name}, master, o);
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(got, expected.out);
  EXPECT_TRUE(is_character_device(name));
  EXPECT_TRUE(others({}).empty());
  ::close(slave);
  ::close(master);
}

TEST_F(Files, AFifoIsWrittenThroughAndStaysAFifo) {
  write("c.toml", short_test_toml());
  const Outcome expected_init = run({"init", "-"});
  ASSERT_EQ(run({"simulate", "--config", "c.toml", "--out", "r.csv"}).status, 0);
  const std::string expected_record = slurp(path("r.csv"));

  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0644), 0);
  const int fd = ::open(path("fifo").c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  Outcome o;
  // Even with --force, a FIFO is written to and never replaced by a file.
  EXPECT_EQ(run_reading({"init", "--force", "fifo"}, fd, o), expected_init.out);
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(run_reading({"simulate", "--config", "c.toml", "--out", "fifo"}, fd, o), expected_record);
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("wrote fifo"), std::string::npos) << o.out;
  ::close(fd);
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(path("fifo"))));
  EXPECT_TRUE(others({"c.toml", "r.csv", "fifo"}).empty());
}

TEST_F(Files, ASymbolicLinkIsFollowedToItsRegularFileAndStaysALink) {
  fs::create_directories(path("results"));
  write("results/config.toml", "# mine\n");
  fs::create_symlink("results/config.toml", path("latest.toml"));

  // Without --force the file it names is not replaced.
  const Outcome refused = run({"init", "latest.toml"});
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("--force"), std::string::npos) << refused.err;
  EXPECT_EQ(slurp(path("results/config.toml")), "# mine\n");

  const Outcome o = run({"init", "--force", "latest.toml"});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(fs::is_symlink(path("latest.toml")));
  EXPECT_EQ(fs::read_symlink(path("latest.toml")), "results/config.toml");
  EXPECT_EQ(slurp(path("results/config.toml")), run({"init", "-"}).out);
  // The temporary went beside the file, and nothing is left anywhere.
  EXPECT_TRUE(others({"results", "latest.toml"}).empty());
  EXPECT_TRUE(others({"config.toml"}, path("results")).empty());

  // --json replaces the earlier result a link names (a result is re-creatable), the link stays.
  fs::create_symlink("results/in.json", path("in.json"));
  write("results/in.json", "{\"gyrocal\": {\"result\": \"inputs\", \"version\": \"0.1.0\"}}\n");
  const Outcome j = run({"inputs", "--beta-deg", "90", "--time-s", "1", "--json", "in.json"});
  ASSERT_EQ(j.status, 0) << j.err;
  EXPECT_TRUE(fs::is_symlink(path("in.json")));
  EXPECT_TRUE(nlohmann::json::parse(slurp(path("results/in.json"))).contains("specific_force_g"));
}

TEST_F(Files, ADanglingSymbolicLinkIsRefused) {
  fs::create_symlink("nowhere/out.toml", path("out.toml"));
  const Outcome o = run({"init", "--force", "out.toml"});
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("'out.toml' is a symbolic link to 'nowhere/out.toml', which does not exist"),
            std::string::npos)
      << o.err;
  EXPECT_TRUE(fs::is_symlink(path("out.toml")));
  EXPECT_TRUE(others({"out.toml"}).empty());
}

TEST_F(Files, AFolderOrASocketAsOutputIsRefusedAndLeftAlone) {
  fs::create_directories(path("folder"));
  const Outcome d = run({"inputs", "--beta-deg", "0", "--time-s", "0", "--json", "folder"});
  EXPECT_EQ(d.status, 1);
  EXPECT_NE(d.err.find("'folder' is a folder"), std::string::npos) << d.err;
  EXPECT_TRUE(fs::is_directory(path("folder")));

  const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(s, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string socket_path = path("sock").string();
  ASSERT_LT(socket_path.size(), sizeof address.sun_path);
  std::strcpy(address.sun_path, socket_path.c_str());
  ASSERT_EQ(::bind(s, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  for (const bool force : {false, true}) {
    std::vector<std::string> args{"init", "sock"};
    if (force) args.push_back("--force");
    const Outcome o = run(args);
    EXPECT_EQ(o.status, 1);
    EXPECT_NE(o.err.find("'sock' is a socket"), std::string::npos) << o.err;
    EXPECT_TRUE(fs::is_socket(fs::symlink_status(path("sock"))));
  }
  ::close(s);
  EXPECT_TRUE(others({"folder", "sock"}).empty());
}

TEST_F(Files, DashIsStandardOutputForEveryOutputOption) {
  write("c.toml", short_test_toml());
  ASSERT_EQ(run({"simulate", "--config", "c.toml", "--out", "r.csv"}).status, 0);
  ASSERT_EQ(run({"calibrate", "r.csv", "--config", "c.toml", "--json", "result.json"}).status, 0);

  const std::vector<std::vector<std::string>> json_commands = {
      {"inputs", "--beta-deg", "90", "--time-s", "1", "--json", "-"},
      {"calibrate", "r.csv", "--config", "c.toml", "--json", "-"},
      {"plan", "--config", "c.toml", "--json", "-"},
      {"sensitivity", "--config", "c.toml", "--json", "-"},
      {"montecarlo", "--config", "c.toml", "--trials", "100", "--json", "-"},
  };
  for (const auto& args : json_commands) {
    const Outcome o = run(args);
    ASSERT_EQ(o.status, 0) << args[0] << ": " << o.err;
    EXPECT_TRUE(nlohmann::json::parse(o.out).is_object()) << args[0];
  }
  const Outcome init = run({"init", "-"});
  EXPECT_EQ(init.status, 0);
  EXPECT_NE(init.out.find("[centrifuge.errors]"), std::string::npos);
  const Outcome report = run({"report", "result.json", "--html", "-"});
  EXPECT_EQ(report.status, 0) << report.err;
  EXPECT_EQ(report.out.rfind("<!DOCTYPE html>", 0), 0u);

  // The record on standard output is the record a file gets; the summary goes to standard error.
  const Outcome sim = run({"simulate", "--config", "c.toml", "--out", "-"});
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_EQ(sim.out, slurp(path("r.csv")));
  EXPECT_NE(sim.err.find("wrote standard output"), std::string::npos) << sim.err;

  // No file named '-' (or anything else) appeared.
  EXPECT_TRUE(others({"c.toml", "r.csv", "result.json"}).empty());
}

TEST_F(Files, DemoRefusesDashBecauseItWritesAFolder) {
  const Outcome o = run({"demo", "--out", "-"});
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("standard output cannot hold a folder"), std::string::npos) << o.err;
  EXPECT_TRUE(others({}).empty());
}

// ---- Item 8: interruption
// ----------------------------------------------------------------------------------

/// Waits until `ready` holds or the process has ended; true if it holds.
bool wait_until(pid_t pid, const std::function<bool()>& ready) {
  for (;;) {
    if (ready()) return true;
    siginfo_t info{};
    if (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
        info.si_pid == pid)
      return ready();  // it has ended (and is left for finish() to collect)
    ::usleep(1000);
  }
}

/// An entry of `folder` whose name starts with `prefix` and that holds at least `bytes` (a file) or any
/// entry (a folder).
bool has_entry(const fs::path& folder, const std::string& prefix, std::uintmax_t bytes = 1) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    if (e.path().filename().string().rfind(prefix, 0) != 0) continue;
    if (e.is_directory(ec)) return true;
    if (e.file_size(ec) >= bytes) return true;
  }
  return false;
}

TEST_F(Files, AnInterruptedSimulationLeavesNoTemporary) {
  // A test long enough to be interrupted while it writes (hundreds of MB if it ran to its end).
  Scenario s = default_scenario();
  s.test.revolutions = 5000;
  write("long.toml", scenario_to_toml(s));
  for (const int sig : {SIGINT, SIGTERM}) {
    const pid_t pid = spawn({"simulate", "--config", "long.toml", "--out", "r.csv"}, -1, [] {
      // Should it not stop, it ends at 256 MB.
      const rlimit limit{256u << 20, 256u << 20};
      ::setrlimit(RLIMIT_FSIZE, &limit);
    });
    ASSERT_TRUE(wait_until(pid, [&] { return has_entry(work_, ".r.csv.tmp", 1 << 20); }))
        << "the simulation ended before it could be interrupted";
    ::kill(pid, sig);
    const Outcome o = finish(pid);
    EXPECT_EQ(o.signal, sig) << "status " << o.status << ": " << o.err;
    EXPECT_TRUE(others({"long.toml"}).empty()) << others({"long.toml"}).front();
  }
}

TEST_F(Files, AnInterruptedDemoLeavesNoFolderAndAnExistingOneAsItWas) {
  // A new folder: nothing at all is left.
  const pid_t fresh = spawn({"demo", "--out", "new"});
  ASSERT_TRUE(wait_until(fresh, [&] { return has_entry(work_, ".new.tmp"); }));
  // Once the record is complete in the staging folder, the rest of the demo is still to come.
  const auto staged_record = [&] {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(work_, ec))
      if (fs::exists(e.path() / "record.csv", ec)) return true;
    return false;
  };
  ASSERT_TRUE(wait_until(fresh, staged_record));
  ::kill(fresh, SIGTERM);
  const Outcome o = finish(fresh);
  EXPECT_EQ(o.signal, SIGTERM) << o.err;
  EXPECT_TRUE(others({}).empty()) << others({}).front();

  // An existing folder with an earlier demo (files gyrocal wrote, which demo replaces without --force) and a
  // file of the user: all exactly as before.
  fs::create_directories(path("old"));
  const std::string earlier_record =
      "# gyrocal-record 1\n# generator = gyrocal simulate\ntime_s,gyro_deg_h\n";
  const std::string earlier_result = "{\"gyrocal\": {\"result\": \"calibration\", \"version\": \"0.1.0\"}}\n";
  write("old/record.csv", earlier_record);
  write("old/result.json", earlier_result);
  write("old/notes.txt", "mine\n");
  const pid_t again = spawn({"demo", "--out", "old"});
  ASSERT_TRUE(wait_until(again, [&] { return has_entry(path("old"), ".gyrocal.tmp"); }));
  ::kill(again, SIGINT);
  const Outcome o2 = finish(again);
  EXPECT_EQ(o2.signal, SIGINT) << o2.err;
  EXPECT_TRUE(others({"record.csv", "result.json", "notes.txt"}, path("old")).empty());
  EXPECT_EQ(slurp(path("old/record.csv")), earlier_record);
  EXPECT_EQ(slurp(path("old/result.json")), earlier_result);
  EXPECT_EQ(slurp(path("old/notes.txt")), "mine\n");
  EXPECT_TRUE(others({"old"}).empty());
}

// ---- Item 9: work that cannot be done ---------------------------------------------------------------------

TEST_F(Files, AConfigurationLargerThanTheLimitIsRefusedWithTheLimit) {
  // 2 MiB of comments: valid TOML, but no configuration is that large (limits::kConfigurationBytes, 1 MiB).
  {
    std::ofstream out(path("huge.toml"), std::ios::binary);
    const std::string line = "# " + std::string(1021, 'x') + "\n";
    for (int i = 0; i < 2 * 1024; ++i) out << line;
  }
  const Outcome o = run({"inputs", "--config", "huge.toml", "--beta-deg", "0", "--time-s", "0"});
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("huge.toml"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("larger than 1 MiB"), std::string::npos) << o.err;

  // /dev/zero never ends: it is read only up to the limit. (A bound on memory shows it, where the
  // sanitizers' own reservations allow one.)
  const bool limit_memory = !sanitized();
  const Outcome z = run({"inputs", "--config", "/dev/zero", "--beta-deg", "0", "--time-s", "0"}, [=] {
    if (!limit_memory) return;
    const rlimit limit{1u << 30, 1u << 30};
    ::setrlimit(RLIMIT_AS, &limit);
  });
  EXPECT_EQ(z.status, 1);
  EXPECT_NE(z.err.find("/dev/zero"), std::string::npos) << z.err;
  EXPECT_NE(z.err.find("larger than 1 MiB"), std::string::npos) << z.err;
}

TEST_F(Files, MonteCarloStatesItsMostTrialsAndRefusesMore) {
  const Outcome help = run({"montecarlo", "--help"});
  EXPECT_NE(help.out.find("1000000000"), std::string::npos) << help.out;
  // Limits that end quickly a run that does not refuse: 4 GB of memory, 20 s of processor time.
  const bool limit_memory = !sanitized();
  const auto limited = [=] {
    const rlimit cpu{20, 20};
    ::setrlimit(RLIMIT_CPU, &cpu);
    if (!limit_memory) return;
    const rlimit memory{rlim_t{4} << 30, rlim_t{4} << 30};
    ::setrlimit(RLIMIT_AS, &memory);
  };
  // The maximum the help used to advertise: a sentence with the reason, not an internal error.
  const Outcome o = run({"montecarlo", "--trials", "1099511627776"}, limited);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("--trials 1099511627776 is more than"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("1000000000"), std::string::npos) << o.err;
  const Outcome samples = run({"montecarlo", "--samples", "--trials", "100001"}, limited);
  EXPECT_EQ(samples.status, 1) << samples.err;
  EXPECT_NE(samples.err.find("100000"), std::string::npos) << samples.err;
  const Outcome one = run({"montecarlo", "--trials", "1"});
  EXPECT_EQ(one.status, 1) << one.err;
  EXPECT_NE(one.err.find("at least 2 trials"), std::string::npos) << one.err;
}

/// No file may grow past 64 MiB in a child run under this (the code before the fix would have started an
/// 18 TB file).
void limit_file_size() {
  const rlimit limit{64u << 20, 64u << 20};
  ::setrlimit(RLIMIT_FSIZE, &limit);
}

// 19e6 revolutions at 200 Hz: 9.65e9 samples, within the 1e10 that a test may hold (reduce/feasibility.hpp)
// and at least 231 GB at 24 bytes a row, more than this machine's disk has free.
constexpr int kAbsurdRevolutions = 19000000;

TEST_F(Files, ARecordLargerThanTheFreeSpaceIsRefusedWithItsFigures) {
  Scenario s = default_scenario();
  s.test.revolutions = kAbsurdRevolutions;
  struct statvfs fs {};
  ASSERT_EQ(::statvfs(dir_.c_str(), &fs), 0);
  if (static_cast<double>(fs.f_bavail) * static_cast<double>(fs.f_frsize) > 232e9)
    GTEST_SKIP() << "the test folder's file system has more than 232 GB free: the record would fit";
  write("absurd.toml", scenario_to_toml(s));
  const Outcome o = run({"simulate", "--config", "absurd.toml", "--out", "r.csv"}, limit_file_size);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(others({"absurd.toml"}).empty());
  // The figures: the samples of the four dwells (4 betas, each 19e6 revolutions at 9.9 rad/s, 200 Hz)
  // and the free space.
  const std::regex figures("its ([0-9]+) samples need at least .* has .* free");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.err, m, figures)) << o.err;
  const double dwells = 4 * double{kAbsurdRevolutions} * 2 * std::numbers::pi / 9.9 * 200;
  EXPECT_NEAR(std::stod(m[1].str()), dwells, 1e-6 * dwells);
  EXPECT_NE(o.err.find("'r.csv'"), std::string::npos) << o.err;
}

TEST_F(Files, ARecordOnStandardOutputHasNoSizeCheck) {
  Scenario s = default_scenario();
  s.test.revolutions = kAbsurdRevolutions;
  write("absurd.toml", scenario_to_toml(s));
  int pipe_fds[2];
  ASSERT_EQ(::pipe2(pipe_fds, O_CLOEXEC), 0);  // the child keeps no reading end
  const pid_t pid =
      spawn({"simulate", "--config", "absurd.toml", "--out", "-"}, pipe_fds[1], limit_file_size);
  ::close(pipe_fds[1]);
  std::string head;
  char buffer[4096];
  while (head.size() < 100000) {
    const ssize_t n = ::read(pipe_fds[0], buffer, sizeof buffer);
    if (n <= 0) break;
    head.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(pipe_fds[0]);  // as `| head` does: the writer ends on SIGPIPE
  const Outcome o = finish(pid);
  EXPECT_EQ(o.signal, SIGPIPE) << o.status << ": " << o.err;
  EXPECT_EQ(head.rfind("# gyrocal-record 1\n", 0), 0u);
  EXPECT_GE(head.size(), 100000u);
  EXPECT_TRUE(others({"absurd.toml"}).empty());
}

// ---- Item 11: empty and odd inputs, a demo folder that cannot be ----------------------------------------

TEST_F(Files, AnEmptyConfigurationIsRefusedAsEmptyAndCommentsAloneAreTheDefaults) {
  const std::vector<std::string> inputs{"inputs", "--beta-deg", "90", "--time-s", "1", "--json", "-"};
  write("empty.toml", "");
  write("blank.toml", " \n\t\n");
  for (const char* name : {"empty.toml", "blank.toml"}) {
    std::vector<std::string> args = inputs;
    args.insert(args.end(), {"--config", name});
    const Outcome o = run(args);
    EXPECT_EQ(o.status, 1);
    EXPECT_NE(o.err.find(std::string("Configuration file ") + name + " is empty"), std::string::npos)
        << o.err;
    EXPECT_EQ(o.err.find("cannot be opened"), std::string::npos) << o.err;
    EXPECT_TRUE(o.out.empty());
  }
  // A file of comments was written on purpose: every key keeps its default.
  write("comments.toml", "# the default scenario\n");
  std::vector<std::string> args = inputs;
  args.insert(args.end(), {"--config", "comments.toml"});
  const Outcome commented = run(args);
  ASSERT_EQ(commented.status, 0) << commented.err;
  EXPECT_EQ(commented.out, run(inputs).out);
}

TEST_F(Files, ARecordWithAByteOrderMarkIsRead) {
  write("c.toml", short_test_toml());
  ASSERT_EQ(run({"simulate", "--config", "c.toml", "--out", "r.csv"}).status, 0);
  write("bom.csv", "\xEF\xBB\xBF" + slurp(path("r.csv")));
  const Outcome plain = run({"calibrate", "r.csv", "--config", "c.toml", "--json", "-"});
  const Outcome bom = run({"calibrate", "bom.csv", "--config", "c.toml", "--json", "-"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  ASSERT_EQ(bom.status, 0) << bom.err;
  EXPECT_EQ(nlohmann::json::parse(bom.out)["coefficients"], nlohmann::json::parse(plain.out)["coefficients"]);
}

TEST_F(Files, UnprintableBytesOfARecordAreEscapedInMessages) {
  write("bad.csv", std::string("\xEF\xBB\xBF\x01\xFFnot a record\x1B[2J\n1,2,3\n"));
  const Outcome o = run({"calibrate", "bad.csv"});
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("bad.csv, line 1"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("'\\x01\\xFFnot a record\\x1B[2J'"), std::string::npos) << o.err;
  for (const char c : o.err) {
    const auto byte = static_cast<unsigned char>(c);
    EXPECT_TRUE((byte >= 0x20 && byte < 0x7f) || c == '\n') << "raw byte " << static_cast<int>(byte);
  }
}

TEST_F(Files, DemoIntoAFileIsRefusedNamingIt) {
  write("taken", "a file\n");
  const Outcome o = run({"demo", "--out", "taken"});
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("'taken': it exists and is a file, not a folder"), std::string::npos) << o.err;
  EXPECT_EQ(slurp(path("taken")), "a file\n");
  EXPECT_TRUE(others({"taken"}).empty());
}

TEST_F(Files, DemoIntoAReadOnlyFolderIsRefusedNamingIt) {
  // Permissions do not stop root; /sys refuses every new folder, also to root.
  fs::path folder = path("read-only");
  if (::geteuid() == 0) {
    folder = "/sys";
  } else {
    fs::create_directories(folder);
    fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
  }
  const fs::path target = folder / "demo";
  const Outcome o = run({"demo", "--out", target.string()});
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("'" + target.string() + "': cannot create a folder in '" + folder.string() + "'"),
            std::string::npos)
      << o.err;
  EXPECT_FALSE(fs::exists(target));
}

}  // namespace
}  // namespace gyrocal
