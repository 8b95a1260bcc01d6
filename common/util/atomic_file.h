// AtomicFile: writes a file so that it appears complete or not at all.
//
// Text goes to "<path>.<pid>.tmp"; commit() flushes it to disk and renames it over <path>. Any
// failure (bad directory, full disk, I/O error) throws Error naming <path> and the
// system's reason, and the temporary file is removed, so no partial <path> is ever left.
// A writer that throws before commit() also leaves nothing: the destructor cleans up.
#pragma once

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string_view>
#include <utility>

namespace cohaptic {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path);  ///< creates <path>.tmp; throws Error
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends formatted text (buffered; written out in large chunks).
  template <typename... T>
  void print(fmt::format_string<T...> format, T&&... args) {
    fmt::format_to(fmt::appender(buffer_), format, std::forward<T>(args)...);
    if (buffer_.size() >= kFlushSize) flush_buffer();
  }
  void write(std::string_view text);

  /// Writes what is buffered, syncs, closes and renames the file into place. Throws Error.
  void commit();

 private:
  static constexpr std::size_t kFlushSize = std::size_t{1} << 20;
  void flush_buffer();
  [[noreturn]] void fail(std::string_view doing, int error_number);

  std::filesystem::path path_;
  std::filesystem::path temp_path_;
  std::FILE* file_ = nullptr;
  fmt::memory_buffer buffer_;
};

}  // namespace cohaptic
