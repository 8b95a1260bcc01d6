#include "common/util/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <utility>

#include "common/util/error.h"

namespace cohaptic {

namespace {

std::string reason(int error_number) { return std::generic_category().message(error_number); }

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)) {
  // Unique per process, so concurrent writers of the same file never share a temporary.
  temp_path_ = path_;
  temp_path_ += fmt::format(".{}.tmp", ::getpid());
  errno = 0;
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (file_ == nullptr) {
    const int error_number = errno;
    throw Error(fmt::format("cannot write {}: {} (while creating {})", path_.string(),
                            reason(error_number), temp_path_.string()));
  }
}

AtomicFile::~AtomicFile() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::error_code ignored;
    std::filesystem::remove(temp_path_, ignored);
  }
}

void AtomicFile::write(std::string_view text) {
  buffer_.append(text.data(), text.data() + text.size());
  if (buffer_.size() >= kFlushSize) flush_buffer();
}

void AtomicFile::flush_buffer() {
  if (buffer_.size() == 0) return;
  errno = 0;
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
    fail("writing", errno);
  buffer_.clear();
}

void AtomicFile::commit() {
  flush_buffer();
  errno = 0;
  if (std::fflush(file_) != 0) fail("writing", errno);
  if (::fsync(::fileno(file_)) != 0) fail("syncing", errno);
  std::FILE* file = std::exchange(file_, nullptr);
  if (std::fclose(file) != 0) {
    const int error_number = errno;
    std::error_code ignored;
    std::filesystem::remove(temp_path_, ignored);
    throw Error(fmt::format("cannot write {}: {} (while closing {})", path_.string(),
                            reason(error_number), temp_path_.string()));
  }
  std::error_code error;
  std::filesystem::rename(temp_path_, path_, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(temp_path_, ignored);
    throw Error(fmt::format("cannot write {}: {} (while renaming {} into place)", path_.string(),
                            error.message(), temp_path_.string()));
  }
}

void AtomicFile::fail(std::string_view doing, int error_number) {
  std::fclose(std::exchange(file_, nullptr));
  std::error_code ignored;
  std::filesystem::remove(temp_path_, ignored);
  throw Error(fmt::format("cannot write {}: {} (while {} {})", path_.string(),
                          error_number != 0 ? reason(error_number) : std::string("I/O error"),
                          doing, temp_path_.string()));
}

}  // namespace cohaptic
