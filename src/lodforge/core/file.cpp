#include "lodforge/core/file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

namespace lodforge {

namespace {
constexpr std::size_t kReadBuffer = 1 << 20;

// pwrite until all `size` bytes are at `offset` (short writes and EINTR retried).
Status writeAllAt(int fd, const std::string& path, std::uint64_t offset, const void* data,
                  std::size_t size) {
  const auto* bytes = static_cast<const std::byte*>(data);
  while (size > 0) {
    const ssize_t put = ::pwrite(fd, bytes, size, static_cast<off_t>(offset));
    if (put < 0 && errno == EINTR) continue;
    if (put < 0) return ioErrorFromErrno(path, "write");
    bytes += put;
    size -= static_cast<std::size_t>(put);
    offset += static_cast<std::uint64_t>(put);
  }
  return {};
}

Error notARegularFile(const std::string& path, const struct stat& info) {
  return {ErrorKind::kBadInput, fmt::format("{}: {}", path,
                                            S_ISDIR(info.st_mode) ? "is a directory; give a file"
                                                                  : "not a regular file")};
}
}  // namespace

// --- ByteSource -------------------------------------------------------------------------------

Result<ByteSource> ByteSource::openFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ioErrorFromErrno(path, "open");
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    return notARegularFile(path, info);
  }
  ByteSource source;
  source.name_ = path;
  source.fd_ = fd;
  source.size_ = static_cast<std::uint64_t>(info.st_size);
  source.buffer_.resize(kReadBuffer);
  source.begin_ = source.buffer_.data();
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  return source;
}

ByteSource ByteSource::fromMemory(std::span<const std::byte> bytes, std::string name) {
  ByteSource source;
  source.name_ = std::move(name);
  source.size_ = bytes.size();
  source.begin_ = bytes.data();
  source.available_ = bytes.size();
  return source;
}

ByteSource::ByteSource(ByteSource&& other) noexcept {
  *this = std::move(other);
}

ByteSource& ByteSource::operator=(ByteSource&& other) noexcept {
  if (this == &other) return *this;
  if (fd_ >= 0) ::close(fd_);
  const bool ownBuffer = other.fd_ >= 0;
  name_ = std::move(other.name_);
  fd_ = std::exchange(other.fd_, -1);
  size_ = other.size_;
  buffer_ = std::move(other.buffer_);
  begin_ = ownBuffer ? buffer_.data() : other.begin_;
  available_ = other.available_;
  position_ = other.position_;
  bufferOffset_ = other.bufferOffset_;
  return *this;
}

ByteSource::~ByteSource() {
  if (fd_ >= 0) ::close(fd_);
}

void ByteSource::refill(std::size_t wanted) {
  if (fd_ < 0) return;  // memory sources hold everything already
  // Move the unread tail to the front, grow if one request needs more than the buffer.
  const std::size_t unread = available_ - position_;
  if (wanted > buffer_.size()) buffer_.resize(std::max(wanted, buffer_.size() * 2));
  std::memmove(buffer_.data(), buffer_.data() + position_, unread);
  bufferOffset_ += position_;
  position_ = 0;
  available_ = unread;
  begin_ = buffer_.data();
  while (available_ < wanted) {
    const ssize_t got = ::read(fd_, buffer_.data() + available_, buffer_.size() - available_);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw ErrorException{ioErrorFromErrno(name_, "read")};
    }
    if (got == 0) break;
    available_ += static_cast<std::size_t>(got);
  }
}

std::size_t ByteSource::ensure(std::size_t n) {
  if (available_ - position_ < n) refill(n);
  return std::min(n, available_ - position_);
}

bool ByteSource::read(void* out, std::size_t n) {
  if (n == 0) return true;  // `out` may be null (an empty vector's data)
  if (fd_ >= 0 && n > buffer_.size()) {
    // Bigger than the buffer: straight into `out` (growing the buffer would hold it twice).
    if (n > remaining()) return false;
    const std::size_t buffered = available_ - position_;
    std::memcpy(out, data(), buffered);
    auto* target = static_cast<std::byte*>(out);
    std::size_t done = buffered;
    while (done < n) {
      const ssize_t got = ::read(fd_, target + done, n - done);
      if (got < 0) {
        if (errno == EINTR) continue;
        throw ErrorException{ioErrorFromErrno(name_, "read")};
      }
      if (got == 0) throw ErrorException{ioError(name_, "the file shrank while being read")};
      done += static_cast<std::size_t>(got);
    }
    bufferOffset_ += available_ + (n - buffered);
    available_ = position_ = 0;
    return true;
  }
  if (ensure(n) < n) return false;
  std::memcpy(out, data(), n);
  position_ += n;
  return true;
}

bool ByteSource::skip(std::uint64_t n) {
  if (n > remaining()) return false;
  const std::size_t inBuffer = available_ - position_;
  if (n <= inBuffer) {
    position_ += static_cast<std::size_t>(n);
    return true;
  }
  // Seek past what is not buffered.
  const std::uint64_t target = offset() + n;
  if (::lseek(fd_, static_cast<off_t>(target), SEEK_SET) < 0)
    throw ErrorException{ioErrorFromErrno(name_, "seek")};
  bufferOffset_ = target;
  position_ = 0;
  available_ = 0;
  return true;
}

bool ByteSource::readLine(std::string& line, std::size_t maxLength) {
  line.clear();
  if (ensure(1) == 0) return false;
  while (true) {
    const std::size_t have = available_ - position_;
    const auto* start = reinterpret_cast<const char*>(data());
    const auto* newline = static_cast<const char*>(std::memchr(start, '\n', have));
    const std::size_t take = newline ? static_cast<std::size_t>(newline - start) : have;
    if (line.size() + take > maxLength) {
      throw ErrorException{
          badInputAtByte(name_, offset(), fmt::format("line longer than {} bytes", maxLength))};
    }
    line.append(start, take);
    position_ += take;
    if (newline) {
      ++position_;
      break;
    }
    if (ensure(1) == 0) break;  // last line without a newline
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

// --- OutputFile -------------------------------------------------------------------------------

std::string temporaryPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  for (;;) {
    std::string name = fmt::format("{}.tmp-{}-{}", path, ::getpid(), counter++);
    struct stat info {};
    if (::lstat(name.c_str(), &info) != 0) return name;  // a name nobody holds
  }
}

Result<OutputFile> OutputFile::create(const std::string& path, std::size_t bufferBytes) {
  OutputFile file;
  file.path_ = path;
  // O_EXCL: the temporary is a new file of ours, never one that appeared under that name since.
  do {
    file.tempPath_ = temporaryPathFor(path);
    file.fd_ = ::open(file.tempPath_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  } while (file.fd_ < 0 && errno == EEXIST);
  if (file.fd_ < 0) return ioErrorFromErrno(path, "create");
  file.buffer_.resize(std::max<std::size_t>(bufferBytes, 4096));
  return file;
}

OutputFile::OutputFile(OutputFile&& other) noexcept {
  *this = std::move(other);
}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this == &other) return *this;
  discard();
  path_ = std::move(other.path_);
  tempPath_ = std::move(other.tempPath_);
  fd_ = std::exchange(other.fd_, -1);
  buffer_ = std::move(other.buffer_);
  buffered_ = std::exchange(other.buffered_, 0);
  written_ = std::exchange(other.written_, 0);
  return *this;
}

OutputFile::~OutputFile() {
  discard();
}

void OutputFile::discard() {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
  ::unlink(tempPath_.c_str());
}

Status OutputFile::flush() {
  LODFORGE_TRY(writeOut(buffer_.data(), buffered_));
  buffered_ = 0;
  return {};
}

Status OutputFile::writeOut(const std::byte* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t put = ::write(fd_, data + done, size - done);
    if (put < 0) {
      if (errno == EINTR) continue;
      return ioErrorFromErrno(path_, "write");
    }
    done += static_cast<std::size_t>(put);
  }
  return {};
}

Status OutputFile::write(const void* data, std::size_t size) {
  assert(fd_ >= 0);
  const auto* bytes = static_cast<const std::byte*>(data);
  written_ += size;
  if (size >= buffer_.size()) {
    // Straight from the caller's memory (a GLB's binary chunk, a batch of work records): no
    // copy through the buffer.
    LODFORGE_TRY(flush());
    return writeOut(bytes, size);
  }
  while (size > 0) {
    if (buffered_ == buffer_.size()) LODFORGE_TRY(flush());
    const std::size_t take = std::min(size, buffer_.size() - buffered_);
    std::memcpy(buffer_.data() + buffered_, bytes, take);
    buffered_ += take;
    bytes += take;
    size -= take;
  }
  return {};
}

std::size_t blockForFile(const std::string& path, std::size_t block, std::size_t recordBytes) {
  const Result<std::uint64_t> bytes = fileSize(path);
  if (!bytes) return block;  // the read that follows says what is wrong with the file
  const std::uint64_t records = *bytes / recordBytes;
  return std::max<std::size_t>(1,
                               static_cast<std::size_t>(std::min<std::uint64_t>(block, records)));
}

Result<WorkFile> WorkFile::open(const std::string& path, bool create) {
  WorkFile file;
  file.path_ = path;
  file.fd_ = ::open(path.c_str(), O_RDWR | O_CLOEXEC | (create ? O_CREAT : 0), 0644);
  if (file.fd_ < 0) return ioErrorFromErrno(path, "open");
  return file;
}

WorkFile::WorkFile(WorkFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)) {}

WorkFile& WorkFile::operator=(WorkFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

WorkFile::~WorkFile() {
  if (fd_ >= 0) ::close(fd_);
}

Status WorkFile::readAt(std::uint64_t offset, void* data, std::size_t size) const {
  auto* bytes = static_cast<std::byte*>(data);
  while (size > 0) {
    const ssize_t got = ::pread(fd_, bytes, size, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return ioErrorFromErrno(path_, "read");
    if (got == 0) return ioError(path_, fmt::format("work file ends before byte {}", offset));
    bytes += got;
    size -= static_cast<std::size_t>(got);
    offset += static_cast<std::uint64_t>(got);
  }
  return {};
}

Status WorkFile::writeAt(std::uint64_t offset, const void* data, std::size_t size) const {
  return writeAllAt(fd_, path_, offset, data, size);
}

Status OutputFile::writeAt(std::uint64_t offset, const void* data, std::size_t size) {
  assert(fd_ >= 0);
  return writeAllAt(fd_, path_, offset, data, size);
}

Status OutputFile::appendFileContents(const std::string& path, std::uint64_t bytes) {
  LODFORGE_TRY(flush());
  const int in = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) return ioErrorFromErrno(path, "open");
  std::uint64_t left = bytes;
  // In-kernel copy first (no trip through user space); plain read/write where it is refused.
  while (left > 0) {
    const ssize_t copied = ::copy_file_range(in, nullptr, fd_, nullptr, left, 0);
    if (copied <= 0) break;
    left -= static_cast<std::uint64_t>(copied);
  }
  while (left > 0) {
    const ssize_t got = ::read(in, buffer_.data(), std::min<std::uint64_t>(left, buffer_.size()));
    if (got <= 0) {
      if (got < 0 && errno == EINTR) continue;
      ::close(in);
      return got < 0 ? ioErrorFromErrno(path, "read") : ioError(path, "ended early");
    }
    buffered_ = static_cast<std::size_t>(got);
    if (Status s = flush(); !s.ok()) {
      ::close(in);
      return s;
    }
    left -= static_cast<std::uint64_t>(got);
  }
  ::close(in);
  written_ += bytes;
  return {};
}

Status OutputFile::commit() {
  assert(fd_ >= 0);
  LODFORGE_TRY(flush());
  if (::close(fd_) != 0) {
    fd_ = -1;
    ::unlink(tempPath_.c_str());
    return ioErrorFromErrno(path_, "close");
  }
  fd_ = -1;
  if (::rename(tempPath_.c_str(), path_.c_str()) != 0) {
    Error e = ioErrorFromErrno(path_, "rename the finished file into place");
    ::unlink(tempPath_.c_str());
    return e;
  }
  return {};
}

Status OutputFile::writeWhole(const std::string& path, std::string_view bytes) {
  Result<OutputFile> file = create(path, 4096);
  if (!file) return file.status();
  LODFORGE_TRY(file->write(bytes.data(), bytes.size()));
  return file->commit();
}

// --- MappedFile -------------------------------------------------------------------------------

Result<MappedFile> MappedFile::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ioErrorFromErrno(path, "open");
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    Error e = ioErrorFromErrno(path, "stat");
    ::close(fd);
    return e;
  }
  if (!S_ISREG(info.st_mode)) {
    ::close(fd);
    return notARegularFile(path, info);
  }
  MappedFile file;
  file.path_ = path;
  file.size_ = static_cast<std::size_t>(info.st_size);
  if (file.size_ > 0) {
    void* mapped = ::mmap(nullptr, file.size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (mapped == MAP_FAILED) {
      Error e = ioErrorFromErrno(path, "map");
      ::close(fd);
      return e;
    }
    file.data_ = static_cast<const std::byte*>(mapped);
  }
  ::close(fd);
  return file;
}

MappedFile::MappedFile(MappedFile&& other) noexcept {
  *this = std::move(other);
}

MappedFile& MappedFile::operator=(MappedFile&& other) noexcept {
  if (this == &other) return *this;
  if (data_) ::munmap(const_cast<std::byte*>(data_), size_);
  path_ = std::move(other.path_);
  data_ = std::exchange(other.data_, nullptr);
  size_ = std::exchange(other.size_, 0);
  return *this;
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(const_cast<std::byte*>(data_), size_);
}

// --- helpers ----------------------------------------------------------------------------------

Result<std::uint64_t> fileSize(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return ioErrorFromErrno(path, "stat");
  return static_cast<std::uint64_t>(info.st_size);
}

std::int64_t modifiedTicks(const std::string& path) {
  std::error_code error;
  const auto time = std::filesystem::last_write_time(path, error);
  return error ? 0 : static_cast<std::int64_t>(time.time_since_epoch().count());
}

Result<std::string> readFileToString(const std::string& path, std::uint64_t maxBytes) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  if (source->size() > maxBytes) {
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: {} bytes is more than the {} this reader loads "
                             "at once",
                             path, source->size(), maxBytes)};
  }
  std::string text(source->size(), '\0');
  try {
    if (!source->read(text.data(), text.size())) return ioError(path, "file shrank while reading");
  } catch (const ErrorException& e) {
    return e.error;
  }
  return text;
}

Result<std::vector<std::byte>> readFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return ioError(path, "cannot open");
  const auto size = static_cast<std::size_t>(in.tellg());
  std::vector<std::byte> bytes(size);
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)))
    return ioError(path, "cannot read");
  return bytes;
}

std::string fileStem(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

std::string fileExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace lodforge
