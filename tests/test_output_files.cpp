// AtomicOutputFile and same_file: where an output path leads. A regular file appears only when committed (held
// open or closed between writes), symbolic links are followed to their target, FIFOs and the process's own
// descriptors are written in place, directories, sockets and empty paths are refused, and same_file sees through
// links. Separate from test_outputs.cpp, which tests what a row holds; the commands' view of the same paths is
// test_cli_output_paths.cpp.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "atomic_file.hpp"
#include "phiq/types.hpp"
#include "scratch_path.hpp"

namespace phiq {
namespace {

class OutputFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = phiq::test::test_scratch_path("phiq_output_file_");
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string read(const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  std::vector<std::string> names(const std::filesystem::path& d) {
    std::vector<std::string> v;
    for (auto& e : std::filesystem::directory_iterator(d)) v.push_back(e.path().filename().string());
    std::sort(v.begin(), v.end());
    return v;
  }
  std::filesystem::path dir_;
};

TEST_F(OutputFile, AppearsWhenCommittedAndNotOtherwise) {
  const auto p = dir_ / "a.csv";
  {
    AtomicOutputFile f(p.string());
    f.write("half");
    EXPECT_FALSE(std::filesystem::exists(p));
    EXPECT_TRUE(names(dir_).empty());  // the temporary has no name (O_TMPFILE): nothing a kill -9 could leave
    EXPECT_TRUE(f.temporary_path().empty());
  }
  EXPECT_TRUE(names(dir_).empty());
  AtomicOutputFile f(p.string());
  f.write("whole\n");
  EXPECT_FALSE(f.direct());
  f.finish();
  EXPECT_FALSE(std::filesystem::exists(p));  // finished, not yet published
  f.publish();
  EXPECT_EQ(read(p), "whole\n");
  EXPECT_TRUE(f.temporary_path().empty());
  EXPECT_EQ(names(dir_), std::vector<std::string>{"a.csv"});
}

// Temporaries ("TARGET.tmp-PID") that processes no longer running left in a directory are removed when a file is
// next written there; a running process's (PID 1) and other users' names stay. PID 4194304 is above every pid_max.
TEST_F(OutputFile, StaleTemporariesOfDeadProcessesAreRemoved) {
  const auto d = dir_ / "with_stale_temporaries";  // a path no other test wrote in (each directory is looked at once)
  std::filesystem::create_directories(d);
  for (const char* n : {"a.csv.tmp-4194304", "b.csv.tmp-4194304", "a.csv.tmp-1", "notes.tmp-x", "a.csv.tmp-"})
    std::ofstream(d / n) << "half";
  AtomicOutputFile f((d / "a.csv").string());
  f.write("whole\n");
  f.commit();
  EXPECT_EQ(names(d), (std::vector<std::string>{"a.csv", "a.csv.tmp-", "a.csv.tmp-1", "notes.tmp-x"}));
}

// Hold::kClosedBetweenWrites: the temporary exists from the start, each write appends to it, and it is committed or
// removed as a held-open one is; a direct target (here /dev/null) is held open as ever.
TEST_F(OutputFile, AFileClosedBetweenWritesAppendsAndCommitsAsAnOpenOne) {
  using Hold = AtomicOutputFile::Hold;
  const auto p = dir_ / "a.csv";
  {
    AtomicOutputFile f(p.string(), Hold::kClosedBetweenWrites);
    EXPECT_EQ(names(dir_).size(), 1u);  // created at once
    f.write("dropped");
  }
  EXPECT_TRUE(names(dir_).empty());
  AtomicOutputFile f(p.string(), Hold::kClosedBetweenWrites);
  f.write("t,x\n");
  f.write("");
  f.write("0,1\n");
  EXPECT_EQ(read(f.temporary_path()), "t,x\n0,1\n");  // on disk between writes
  f.commit();
  EXPECT_EQ(read(p), "t,x\n0,1\n");
  EXPECT_THROW(f.write("late"), Error);
  AtomicOutputFile null("/dev/null", Hold::kClosedBetweenWrites);
  EXPECT_TRUE(null.direct());
  null.write("x");
  null.commit();
}

// A chain of relative links into another directory: the last target is replaced, the temporary made beside it, the
// links stay.
TEST_F(OutputFile, SymbolicLinksAreFollowedToTheirTarget) {
  std::filesystem::create_directories(dir_ / "data");
  std::ofstream(dir_ / "data" / "t.csv") << "old\n";
  std::filesystem::create_symlink("t.csv", dir_ / "data" / "hop.csv");
  std::filesystem::create_symlink("data/hop.csv", dir_ / "link.csv");
  const OutputPath where = resolve_output_path((dir_ / "link.csv").string());
  EXPECT_EQ(where.target, (dir_ / "data" / "t.csv").string());
  EXPECT_TRUE(where.exists);
  EXPECT_FALSE(where.direct);
  // (a named temporary shows where it is made: beside the target)
  AtomicOutputFile f((dir_ / "link.csv").string(), AtomicOutputFile::Hold::kClosedBetweenWrites);
  EXPECT_EQ(std::filesystem::path(f.temporary_path()).parent_path(), dir_ / "data");
  f.write("new\n");
  f.commit();
  EXPECT_EQ(read(dir_ / "data" / "t.csv"), "new\n");
  EXPECT_TRUE(std::filesystem::is_symlink(dir_ / "link.csv"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir_ / "data" / "hop.csv"));
  EXPECT_EQ(names(dir_ / "data"), (std::vector<std::string>{"hop.csv", "t.csv"}));
  // a loop of links is refused, naming the path
  std::filesystem::create_symlink("loop2", dir_ / "loop1");
  std::filesystem::create_symlink("loop1", dir_ / "loop2");
  try {
    AtomicOutputFile loop((dir_ / "loop1").string());
    ADD_FAILURE() << "a loop of links accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("loop1: cannot write: Too many levels of symbolic links"), std::string::npos)
        << e.what();
  }
}

// A FIFO (and a pipe reached as /dev/fd/N) is written in place, streamed, with no temporary beside it.
TEST_F(OutputFile, FifosAndOwnDescriptorsAreWrittenInPlace) {
  const auto fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = read(fifo); });
  {
    AtomicOutputFile f(fifo.string());  // waits for the reader
    EXPECT_TRUE(f.direct());
    EXPECT_TRUE(f.temporary_path().empty());
    f.write("through\n");
    f.commit();
  }
  reader.join();
  EXPECT_EQ(got, "through\n");
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_EQ(names(dir_), std::vector<std::string>{"fifo"});

  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string path = "/dev/fd/" + std::to_string(fds[1]);
  EXPECT_EQ(resolve_output_path(path).descriptor, fds[1]);
  {
    AtomicOutputFile f(path);
    EXPECT_TRUE(f.direct());
    f.write("piped");
    f.commit();
  }
  ::close(fds[1]);  // the file's copy of the descriptor is closed too: the reader sees the end
  char buf[16] = {};
  EXPECT_EQ(::read(fds[0], buf, sizeof buf), 5);
  EXPECT_EQ(std::string(buf), "piped");
  ::close(fds[0]);
}

TEST_F(OutputFile, DirectoriesSocketsAndEmptyPathsAreRefused) {
  EXPECT_THROW(AtomicOutputFile(""), Error);
  try {
    AtomicOutputFile f(dir_.string());
    ADD_FAILURE() << "a directory accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), dir_.string() + ": cannot write: is a directory");
  }
  const auto sock = dir_ / "sock";
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", sock.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  EXPECT_THROW(AtomicOutputFile(sock.string()), Error);
  ::close(fd);
  EXPECT_EQ(names(dir_), std::vector<std::string>{"sock"});  // nothing created beside it
}

TEST_F(OutputFile, SameFileSeesLinksAndFilesToBe) {
  const auto a = dir_ / "a.yaml";
  std::ofstream(a) << "x";
  std::filesystem::create_symlink("a.yaml", dir_ / "l.yaml");
  std::filesystem::create_hard_link(a, dir_ / "h.yaml");
  std::filesystem::create_directories(dir_ / "sub");
  EXPECT_TRUE(same_file(a.string(), (dir_ / "l.yaml").string()));
  EXPECT_TRUE(same_file(a.string(), (dir_ / "h.yaml").string()));
  EXPECT_TRUE(same_file(a.string(), (dir_ / "sub" / ".." / "a.yaml").string()));
  EXPECT_TRUE(same_file((dir_ / "new.csv").string(), (dir_ / "sub" / ".." / "new.csv").string()));  // neither exists
  std::filesystem::create_symlink("new.csv", dir_ / "to_new.csv");  // dangling, to the same file to be
  EXPECT_TRUE(same_file((dir_ / "new.csv").string(), (dir_ / "to_new.csv").string()));
  EXPECT_FALSE(same_file(a.string(), (dir_ / "new.csv").string()));
  EXPECT_FALSE(same_file((dir_ / "new.csv").string(), (dir_ / "other.csv").string()));
}

}  // namespace
}  // namespace phiq
