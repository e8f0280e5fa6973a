#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/interrupt.h"

namespace arcwheel::hdf5 {
namespace {

constexpr const char* kHdf5ChildStage = "hdf5";

bool g_in_child = false;

double DefaultTimeoutS(const std::filesystem::path& path) {
  std::error_code error;
  const auto bytes = std::filesystem::file_size(path, error);
  return 60.0 + (error ? 0.0 : static_cast<double>(bytes) / 10e6);
}

// Waits for `child`; its wait status, or nothing once `timeout_s` has passed or a signal asks us
// to stop (the child is then killed and reaped). `exit_pipe` (or -1) is a pipe's read end whose
// write end only the child holds: it reports end of file the moment the child exits, so the wait
// ends then, not at the next of a series of growing sleeps (up to 20 ms late).
std::optional<int> WaitFor(pid_t child, double timeout_s, int exit_pipe) {
  const auto start = std::chrono::steady_clock::now();
  auto pause = std::chrono::microseconds(200);
  for (;;) {
    int status = 0;
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) return status;
    if (done < 0 && errno != EINTR) return 0;  // reaped elsewhere: nothing to report
    const std::chrono::duration<double> waited = std::chrono::steady_clock::now() - start;
    if (InterruptRequested() || waited.count() > timeout_s) {
      kill(child, SIGKILL);
      while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
      }
      return std::nullopt;
    }
    if (exit_pipe >= 0) {
      // At most 20 ms at a time, so that an interrupt is still seen within 20 ms.
      pollfd exited{.fd = exit_pipe, .events = POLLIN, .revents = 0};
      if (poll(&exited, 1, 20) > 0) {
        // The child has closed its end: it is exiting (its memory already given back), and can be
        // reaped within microseconds. Short sleeps from here on, not a blocking wait, in case a
        // damaged file made it close the pipe and hang.
        exit_pipe = -1;
        pause = std::chrono::microseconds(20);
      }
      continue;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
}

// Runs `read` in a child process: false when no child could be started (or this is one already),
// true when the child finished (whether its read succeeded or refused the file); throws when it
// crashed or did not finish in time.
bool RunInChildProcess(const std::filesystem::path& path, const std::function<void()>& read,
                       double timeout_s) {
  if (g_in_child) return false;
  if (timeout_s <= 0.0) timeout_s = DefaultTimeoutS(path);
  std::fflush(nullptr);  // nothing buffered twice
  int exit_pipe[2] = {-1, -1};
  if (pipe2(exit_pipe, O_CLOEXEC) != 0) exit_pipe[0] = exit_pipe[1] = -1;  // WaitFor then polls
  const pid_t child = fork();
  if (child < 0) {  // no child to be had: the caller reads, unguarded, as before
    for (const int end : exit_pipe) {
      if (end >= 0) close(end);
    }
    return false;
  }
  if (child == 0) {
    g_in_child = true;
    if (exit_pipe[0] >= 0) close(exit_pipe[0]);
    try {
      read();
    } catch (...) {
      // Refused: the parent reads again and gives the reader's own message.
    }
    _exit(0);
  }
  if (exit_pipe[1] >= 0) close(exit_pipe[1]);
  const std::optional<int> status = WaitFor(child, timeout_s, exit_pipe[0]);
  if (exit_pipe[0] >= 0) close(exit_pipe[0]);
  ThrowIfInterrupted();
  const std::string name = fmt::format("'{}'", path.string());
  if (!status) {
    throw Error(ErrorCode::kBadInput, kHdf5ChildStage,
                fmt::format("{}: libhdf5 had not finished reading it after {:g} s (a damaged file?)", name,
                            timeout_s));
  }
  if (WIFSIGNALED(*status)) {
    const int signal = WTERMSIG(*status);
    throw Error(ErrorCode::kBadInput, kHdf5ChildStage,
                name + ": reading it crashed libhdf5 (signal " + std::to_string(signal) + ", " +
                    strsignal(signal) + "); the file is damaged");
  }
  if (!WIFEXITED(*status) || WEXITSTATUS(*status) != 0) {
    throw Error(ErrorCode::kBadInput, kHdf5ChildStage,
                name + ": reading it crashed libhdf5 (exit status " +
                    std::to_string(WIFEXITED(*status) ? WEXITSTATUS(*status) : -1) +
                    "); the file is damaged");
  }
  return true;
}

// The first page of the memory file: which arrays it holds and where.
constexpr std::uint32_t kMagic = 0x61726377;  // "arcw"
constexpr std::size_t kPage = 4096;
// Bytes copied out before their pages are given back: small enough for the copy's buffer to stay
// in the cache, large enough that the system calls do not count.
constexpr std::size_t kCopyChunk = 1u << 20;

std::size_t RoundUpToPage(std::size_t bytes) { return (bytes + kPage - 1) / kPage * kPage; }

[[noreturn]] void ThrowSystemError(const std::string& what) {
  throw Error(ErrorCode::kIo, kHdf5ChildStage, what + ": " + std::strerror(errno));
}

// `length` bytes of `fd` from `offset` into `data`; Error{kIo} when they are not all there.
void ReadExactly(int fd, char* data, std::size_t length, off_t offset) {
  while (length > 0) {
    const ssize_t got = pread(fd, data, length, offset);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) ThrowSystemError("cannot read the shared memory");
    data += got;
    length -= static_cast<std::size_t>(got);
    offset += got;
  }
}

}  // namespace

SharedArrays::SharedArrays() : fd_(memfd_create("arcwheel-arrays", MFD_CLOEXEC)) {
  static_assert(sizeof(Directory) <= kPage);
  if (fd_ < 0) ThrowSystemError("cannot create shared memory for the child reader");
  directory_.magic = kMagic;
}

SharedArrays::~SharedArrays() {
  for (const auto& [address, bytes] : mappings_) munmap(address, bytes);
  close(fd_);
}

SharedArrays::Entry& SharedArrays::AddEntry(const std::string& name, std::size_t count,
                                            std::size_t value_bytes) {
  if (directory_.arrays == kMaxArrays || name.size() >= sizeof(Entry::name)) {
    throw Error(ErrorCode::kInternal, kHdf5ChildStage,
                "too many shared arrays, or the name '" + name + "' is too long");
  }
  Entry& entry = directory_.entries[directory_.arrays++];
  std::memcpy(entry.name, name.c_str(), name.size() + 1);
  entry.value_bytes = static_cast<std::uint32_t>(value_bytes);
  entry.count = count;
  return entry;
}

void* SharedArrays::Allocate(const std::string& name, std::size_t count, std::size_t value_bytes) {
  Entry& entry = AddEntry(name, count, value_bytes);
  entry.offset = end_;
  const std::size_t bytes = count * value_bytes;
  if (bytes == 0) return nullptr;
  end_ = RoundUpToPage(end_ + bytes);
  if (ftruncate(fd_, static_cast<off_t>(end_)) != 0) ThrowSystemError("cannot grow the shared memory");
  // Populated at once: the pages are allocated in one pass, not by a fault per 4 KiB as libhdf5
  // writes them.
  void* address = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_POPULATE, fd_,
                       static_cast<off_t>(entry.offset));
  if (address == MAP_FAILED) ThrowSystemError("cannot map the shared memory");
  mappings_.emplace_back(address, bytes);
  return address;
}

std::optional<SharedArrays::FileIdentity> SharedArrays::IdentityOf(int fd) {
  struct stat status {};
  if (fd < 0 || fstat(fd, &status) != 0) return std::nullopt;
  return FileIdentity{
      .device = status.st_dev,
      .inode = status.st_ino,
      .bytes = static_cast<std::uint64_t>(status.st_size),
      .modified_ns = std::int64_t{status.st_mtim.tv_sec} * 1'000'000'000 + status.st_mtim.tv_nsec};
}

void SharedArrays::LeaveInFile(const std::string& name, const FileExtent& extent, std::size_t value_bytes) {
  const int fd = open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  const std::optional<FileIdentity> identity = IdentityOf(fd);
  if (fd >= 0) close(fd);
  if (!identity) ThrowSystemError(fmt::format("cannot stat '{}'", path_.string()));
  Entry& entry = AddEntry(name, extent.count, value_bytes);
  entry.in_file = 1;
  entry.offset = extent.offset;
  directory_.file = *identity;
}

void SharedArrays::MarkComplete() {
  directory_.complete = 1;
  if (pwrite(fd_, &directory_, sizeof directory_, 0) != static_cast<ssize_t>(sizeof directory_)) {
    ThrowSystemError("cannot write the shared memory's directory");
  }
}

bool SharedArrays::ReadDirectory() {
  Directory directory;
  if (pread(fd_, &directory, sizeof directory, 0) != static_cast<ssize_t>(sizeof directory)) return false;
  if (directory.magic != kMagic || directory.complete != 1 || directory.arrays > kMaxArrays) return false;
  directory_ = directory;
  return true;
}

const SharedArrays::Entry* SharedArrays::Find(const std::string& name, std::size_t value_bytes) const {
  for (std::uint32_t k = 0; k < directory_.arrays; ++k) {
    const Entry& entry = directory_.entries[k];
    if (name == entry.name && entry.value_bytes == value_bytes) return &entry;
  }
  return nullptr;
}

void SharedArrays::MoveOut(const Entry& entry, const std::function<void(const void*, std::size_t)>& append) {
  const std::size_t bytes = entry.count * entry.value_bytes;
  // Read with pread into a small buffer that stays in cache, not through a mapping of the memory
  // file: a mapping costs a page fault per 4 KiB read, and unmapping it another pass. Chunks of
  // whole pages and whole values, each given back to the system once copied, so that the array
  // is never held twice in full.
  const std::size_t chunk = kCopyChunk / entry.value_bytes * entry.value_bytes;
  std::vector<char> buffer(std::min(chunk, bytes));
  for (std::size_t done = 0; done < bytes;) {
    const std::size_t length = std::min(chunk, bytes - done);
    const auto offset = static_cast<off_t>(entry.offset + done);
    ReadExactly(fd_, buffer.data(), length, offset);
    append(buffer.data(), length / entry.value_bytes);
    fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, offset, static_cast<off_t>(length));
    done += length;
  }
}

std::shared_ptr<void> SharedArrays::MapFile(const Entry& entry) const {
  const std::size_t bytes = entry.count * entry.value_bytes;
  const int fd = open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) ThrowSystemError(fmt::format("cannot open '{}'", path_.string()));
  const std::optional<FileIdentity> identity = IdentityOf(fd);
  const bool same = identity == directory_.file && entry.offset + bytes <= identity->bytes;
  if (!same) {
    close(fd);
    throw Error(ErrorCode::kBadInput, kHdf5ChildStage,
                fmt::format("'{}' was replaced or changed while it was read: read it again", path_.string()));
  }
  if (bytes == 0) {
    close(fd);
    return nullptr;
  }
  // Private, writable, and populated for reading: the page cache's own pages, mapped in one pass
  // of the kernel, and a page copied only where a reading is marked invalid. Populating a writable
  // private mapping with MAP_POPULATE would copy every page; MADV_POPULATE_READ (Linux 5.14) maps
  // them for reading only. An older kernel gets them populated read-only and then made writable,
  // a second pass over the page tables. (Truncating the file while it is mapped would end this
  // process with SIGBUS: a scan is not rewritten in place while it is processed.)
  const std::uint64_t start = entry.offset / kPage * kPage;
  const std::size_t length = bytes + static_cast<std::size_t>(entry.offset - start);
  void* address = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE, fd, static_cast<off_t>(start));
  if (address != MAP_FAILED && madvise(address, length, MADV_POPULATE_READ) != 0) {
    munmap(address, length);
    address = mmap(nullptr, length, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, static_cast<off_t>(start));
    if (address != MAP_FAILED && mprotect(address, length, PROT_READ | PROT_WRITE) != 0) {
      munmap(address, length);
      address = MAP_FAILED;
    }
  }
  close(fd);
  if (address == MAP_FAILED) ThrowSystemError(fmt::format("cannot map '{}'", path_.string()));
  const std::shared_ptr<void> mapping(address, [length](void* mapped) { munmap(mapped, length); });
  return {mapping, static_cast<char*>(address) + (entry.offset - start)};
}

std::shared_ptr<void> SharedArrays::Map(const Entry& entry) const {
  if (entry.in_file != 0) return MapFile(entry);
  const std::size_t bytes = entry.count * entry.value_bytes;
  if (bytes == 0) return nullptr;
  // Populated at once: one pass of the kernel over the pages instead of a fault per 4 KiB later.
  void* address = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_POPULATE, fd_,
                       static_cast<off_t>(entry.offset));
  if (address == MAP_FAILED) ThrowSystemError("cannot map the shared memory");
  // The mapping keeps the memory file's pages after the file itself is closed.
  return {address, [bytes](void* mapped) { munmap(mapped, bytes); }};
}

void ReadFirstInChildProcess(const std::filesystem::path& path, const std::function<void()>& read,
                             double timeout_s) {
  (void)RunInChildProcess(path, read, timeout_s);
}

bool ReadInChildProcess(const std::filesystem::path& path, SharedArrays& arrays,
                        const std::function<void(SharedArrays&)>& read, double timeout_s) {
  arrays.path_ = path;
  const bool ran = RunInChildProcess(
      path,
      [&] {
        read(arrays);
        arrays.MarkComplete();
      },
      timeout_s);
  return ran && arrays.ReadDirectory();
}

}  // namespace arcwheel::hdf5
