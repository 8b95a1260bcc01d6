#include "common/fem/compliance_disk_cache.h"

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fmt/format.h>
#include <fstream>
#include <mutex>
#include <thread>

#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace cohaptic {
namespace {

constexpr char kMagic[8] = {'C', 'H', 'C', 'O', 'M', 'P', 'L', '\0'};

// A digest computed on a thread of its own from the pieces handed to it, in order, so that
// reading the next piece overlaps hashing the last. A piece is either copied (small
// values) or kept by pointer (a column, whose memory stays put until finish()).
class PipelinedHasher {
 public:
  PipelinedHasher() : thread_([this] { hash_pieces(); }) {}
  ~PipelinedHasher() { stop(); }
  PipelinedHasher(const PipelinedHasher&) = delete;
  PipelinedHasher& operator=(const PipelinedHasher&) = delete;

  void copy(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const char*>(data);
    push({nullptr, 0, std::vector<char>(bytes, bytes + size)});
  }
  void keep(const void* data, std::size_t size) { push({data, size, {}}); }
  /// The digest of every piece; the thread has stopped.
  Digest finish() {
    stop();
    return hasher_.finish();
  }

 private:
  struct Piece {
    const void* kept;
    std::size_t size;
    std::vector<char> copied;
  };
  void push(Piece piece) {
    {
      const std::lock_guard lock(mutex_);
      pieces_.push_back(std::move(piece));
    }
    ready_.notify_one();
  }
  void stop() {
    {
      const std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    ready_.notify_one();
    if (thread_.joinable()) thread_.join();
  }
  void hash_pieces() {
    std::unique_lock lock(mutex_);
    while (true) {
      ready_.wait(lock, [this] { return stopping_ || !pieces_.empty(); });
      if (pieces_.empty()) return;  // stopping, and everything handed over is hashed
      const Piece piece = std::move(pieces_.front());
      pieces_.pop_front();
      lock.unlock();
      if (piece.kept)
        hasher_.bytes(piece.kept, piece.size);
      else
        hasher_.bytes(piece.copied.data(), piece.copied.size());
      lock.lock();
    }
  }

  ContentHasher hasher_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Piece> pieces_;
  bool stopping_ = false;
  std::thread thread_;  // last: it starts once the rest is ready
};

// Reads plain values from a cache file, up to its checksum, hashing every byte it reads: the
// columns go straight from the file into their matrices while the last one is hashed, and
// the checksum is known soon after the last one is read (one pass, no copy of the file).
struct HashingReader {
  std::ifstream& in;
  std::uintmax_t remaining;  // bytes left before the checksum
  PipelinedHasher hasher;
  bool read(void* out, std::size_t size) {
    if (size > remaining || !in.read(static_cast<char*>(out), static_cast<std::streamsize>(size)))
      return false;
    remaining -= size;
    return true;
  }
  bool bytes(void* out, std::size_t size) {
    if (!read(out, size)) return false;
    hasher.copy(out, size);
    return true;
  }
  /// A column's values, hashed from where they were read to: `out` must stay put.
  bool column(double* out, std::size_t count) {
    if (!read(out, count * sizeof(double))) return false;
    hasher.keep(out, count * sizeof(double));
    return true;
  }
  template <typename T>
  bool value(T& v) {
    return bytes(&v, sizeof v);
  }
};

// Writes plain values to a cache file through `out`, hashing every byte written, on the
// hasher's thread: a column is hashed from where it lies (it must stay put until finish()).
struct HashingWriter {
  AtomicFile& out;
  PipelinedHasher hasher;
  void bytes(const void* data, std::size_t size) {
    out.write(std::string_view(static_cast<const char*>(data), size));
    hasher.copy(data, size);
  }
  void column(const double* data, std::size_t count) {
    out.write(std::string_view(reinterpret_cast<const char*>(data), count * sizeof(double)));
    hasher.keep(data, count * sizeof(double));
  }
  template <typename T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
};

}  // namespace

Digest compliance_cache_key(const TetMesh& mesh, const LinearElasticMaterial& material,
                            const DofMap& dofs, const std::vector<int>& row_nodes,
                            ComplianceRoute route) {
  ContentHasher h;
  h.text("cohaptic compliance cache").value(kComplianceCacheFormatVersion);
  h.matrix(mesh.nodes);
  h.values(std::span<const Tet>(mesh.tets));
  h.value(material.youngs_modulus)
      .value(material.poisson_ratio)
      .value(static_cast<int>(material.formulation));
  h.values(std::span<const AxisMask>(dofs.fixed_axes));
  h.values(std::span<const int>(row_nodes));
  h.value(static_cast<int>(route));
  return h.finish();
}

std::filesystem::path compliance_cache_file(const std::filesystem::path& directory,
                                            const Digest& key) {
  return directory / ("compliance-" + to_hex(key).substr(0, 32) + ".bin");
}

ComplianceCacheLoad load_compliance_cache(const std::filesystem::path& file, const Digest& key,
                                          ComplianceColumns& columns, ProgressLog* progress) {
  ComplianceCacheLoad result;
  std::ifstream in(file, std::ios::binary);
  std::error_code size_error;
  const std::uintmax_t file_size = std::filesystem::file_size(file, size_error);
  if (!in || size_error) {
    result.problem = "no cache file";
    return result;
  }
  Digest stored_checksum{};
  if (file_size < sizeof kMagic + stored_checksum.size()) {
    result.problem = fmt::format("truncated ({} bytes)", file_size);
    return result;
  }
  // Declared before the reader, so that its hashing thread, which reads them, stops first.
  std::vector<std::pair<int, ComplianceColumn>> loaded;
  HashingReader r{in, file_size - stored_checksum.size(), {}};
  char magic[sizeof kMagic];
  std::uint32_t version = 0;
  Digest stored_key{};
  if (!r.bytes(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
    result.problem = "not a cohaptic compliance cache";
    return result;
  }
  if (!r.value(version) || version != kComplianceCacheFormatVersion) {
    result.problem = fmt::format("format version {} (this build reads {})", version,
                                 kComplianceCacheFormatVersion);
    return result;
  }
  if (!r.value(stored_key) || stored_key != key) {
    result.problem = "computed for a different mesh, material or boundary conditions";
    return result;
  }
  std::uint32_t row_count = 0;
  if (!r.value(row_count) || row_count != columns.row_nodes().size()) {
    result.problem = "row count differs";
    return result;
  }
  std::vector<int> rows(row_count);
  if (!r.bytes(rows.data(), rows.size() * sizeof(int)) || rows != columns.row_nodes()) {
    result.problem = "row nodes differ";
    return result;
  }
  std::uint32_t column_count = 0;
  if (!r.value(column_count)) {
    result.problem = "truncated column count";
    return result;
  }
  const std::uintmax_t column_bytes = sizeof(int) + 9 * std::uintmax_t{row_count} * sizeof(double);
  if (column_count > r.remaining / column_bytes) {
    result.problem =
        fmt::format("{} columns announced, {} bytes left for them", column_count, r.remaining);
    return result;
  }
  loaded.reserve(column_count);
  if (progress) progress->set_total(column_count);
  for (std::uint32_t c = 0; c < column_count; ++c) {
    int node = 0;
    if (!r.value(node)) {
      result.problem = fmt::format("truncated at column {}", c);
      return result;
    }
    if (node < 0 || node >= columns.volume_node_count()) {
      result.problem = fmt::format("column {} names node {}, outside the mesh", c, node);
      return result;
    }
    ComplianceColumn& column =
        loaded.emplace_back(node, ComplianceColumn(3 * static_cast<Eigen::Index>(row_count), 3))
            .second;
    if (!r.column(column.data(), static_cast<std::size_t>(column.size()))) {
      result.problem = fmt::format("truncated at column {}", c);
      return result;
    }
    if (progress) progress->add(1);
  }
  if (r.remaining != 0) {
    result.problem = "trailing bytes after the last column";
    return result;
  }
  if (!in.read(reinterpret_cast<char*>(stored_checksum.data()), stored_checksum.size()) ||
      r.hasher.finish() != stored_checksum) {
    result.problem = "checksum mismatch (truncated or corrupted)";
    return result;
  }
  for (auto& [node, column] : loaded) columns.insert_column(node, std::move(column));
  result.loaded = true;
  result.columns = static_cast<int>(loaded.size());
  return result;
}

void save_compliance_cache(const std::filesystem::path& file, const Digest& key,
                           const ComplianceColumns& columns, ProgressLog* progress) {
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  if (ec)
    throw Error(fmt::format("{}: cannot create the cache directory: {}",
                            file.parent_path().string(), ec.message()));
  // Sorted by node so the same columns always give the same file.
  std::vector<int> nodes;
  for (const auto& entry : columns.columns()) nodes.push_back(entry.first);
  std::sort(nodes.begin(), nodes.end());
  if (progress) progress->set_total(static_cast<double>(nodes.size()));

  AtomicFile out(file);
  HashingWriter w{out, {}};
  w.bytes(kMagic, sizeof kMagic);
  w.value(kComplianceCacheFormatVersion);
  w.value(key);
  const auto& rows = columns.row_nodes();
  w.value(static_cast<std::uint32_t>(rows.size()));
  w.bytes(rows.data(), rows.size() * sizeof(int));
  w.value(static_cast<std::uint32_t>(nodes.size()));
  for (int node : nodes) {
    const ComplianceColumn& column = columns.columns().at(node);
    w.value(node);
    w.column(column.data(), static_cast<std::size_t>(column.size()));
    if (progress) progress->add(1);
  }
  const Digest checksum = w.hasher.finish();
  out.write(std::string_view(reinterpret_cast<const char*>(checksum.data()), checksum.size()));
  if (progress) progress->set_phase("syncing " + file.string() + " to disk");
  out.commit();
}

}  // namespace cohaptic
