#include "common/separation/separation_field_cache.h"

#include <algorithm>
#include <cstring>
#include <fmt/format.h>

#include "common/util/checksummed_file.h"

namespace cohaptic {
namespace {

constexpr char kMagic[8] = {'C', 'H', 'S', 'E', 'P', 'A', 'R', '\0'};

// Everything before the values, written and read as one block.
struct Header {
  char magic[8];
  std::uint32_t version;
  Digest key;
  std::int32_t degree;
  std::int32_t node_count;
  std::int32_t tool_node_count;
  std::uint64_t value_count;
};
static_assert(sizeof(Header) == 64,
              "the header has no padding: its bytes are checksummed as they are");

void hash_body(ContentHasher& h, const SeparationBody& body) {
  h.matrix(body.mesh.nodes);
  h.values(std::span<const Tet>(body.mesh.tets));
  h.value(body.material.youngs_modulus)
      .value(body.material.poisson_ratio)
      .value(static_cast<int>(body.material.formulation));
  h.values(std::span<const AxisMask>(body.fixed_axes));
}

}  // namespace

Digest separation_fields_key(const SeparationBodies& bodies, const SeparationInterface& interface,
                             const FieldSettings& settings) {
  ContentHasher h;
  h.text("cohaptic separation fields").value(kSeparationCacheFormatVersion);
  hash_body(h, bodies.pulled);
  hash_body(h, bodies.base);
  h.values(std::span<const int>(interface.pulled_nodes));
  h.values(std::span<const int>(interface.base_nodes));
  h.values(std::span<const Triangle>(interface.triangles));
  h.value(settings.degree).value(settings.samples_per_axis).value(settings.max_deflection);
  h.values(std::span<const double>(settings.footprint_radii));
  return h.finish();
}

std::filesystem::path separation_fields_file(const std::filesystem::path& directory,
                                             const Digest& key) {
  return directory / ("separation-" + to_hex(key).substr(0, 32) + ".bin");
}

SeparationFieldsLoad load_separation_fields(const std::filesystem::path& file, const Digest& key) {
  SeparationFieldsLoad result;
  Header header{};
  const ChecksummedRead read = read_checksummed_file(file, sizeof header);
  if (!read.problem.empty()) {
    result.problem = read.problem;
    return result;
  }
  std::memcpy(&header, read.body.data(), sizeof header);
  if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0) {
    result.problem = "not a cohaptic separation-fields cache";
    return result;
  }
  if (header.version != kSeparationCacheFormatVersion) {
    result.problem = fmt::format("format version {} (this build reads {})", header.version,
                                 kSeparationCacheFormatVersion);
    return result;
  }
  if (header.key != key) {
    result.problem = "computed for different bodies, interface or field settings";
    return result;
  }
  const std::uint64_t expected = static_cast<std::uint64_t>(std::max(header.node_count, 0)) *
                                 static_cast<std::uint64_t>(std::max(header.tool_node_count, 0)) *
                                 kFieldStates *
                                 SeparationFields::block_size(std::max(header.degree, 0));
  if (header.degree < 1 || header.node_count < 1 || header.tool_node_count < 1 ||
      header.value_count != expected ||
      read.body.size() != sizeof header + expected * sizeof(double)) {
    result.problem =
        fmt::format("inconsistent sizes (degree {}, {} nodes, {} tool nodes, {} values, {} bytes)",
                    header.degree, header.node_count, header.tool_node_count, header.value_count,
                    read.body.size());
    return result;
  }
  result.fields.degree = header.degree;
  result.fields.node_count = header.node_count;
  result.fields.tool_node_count = header.tool_node_count;
  result.fields.values.resize(expected);
  std::memcpy(result.fields.values.data(), read.body.data() + sizeof header,
              expected * sizeof(double));
  result.loaded = true;
  return result;
}

void save_separation_fields(const std::filesystem::path& file, const Digest& key,
                            const SeparationFields& fields) {
  Header header{};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  header.version = kSeparationCacheFormatVersion;
  header.key = key;
  header.degree = fields.degree;
  header.node_count = fields.node_count;
  header.tool_node_count = fields.tool_node_count;
  header.value_count = fields.values.size();
  std::vector<char> bytes(sizeof header + fields.values.size() * sizeof(double));
  std::memcpy(bytes.data(), &header, sizeof header);
  std::memcpy(bytes.data() + sizeof header, fields.values.data(),
              fields.values.size() * sizeof(double));
  write_checksummed_file(file, std::string_view(bytes.data(), bytes.size()));
}

CachedSeparationFields cached_separation_fields(const std::filesystem::path& directory,
                                                const SeparationBodies& bodies,
                                                const SeparationInterface& interface,
                                                const FieldSettings& settings) {
  validate(settings);
  const Digest key = separation_fields_key(bodies, interface, settings);
  const std::filesystem::path file = separation_fields_file(directory, key);
  CachedSeparationFields cached;
  SeparationFieldsLoad load = load_separation_fields(file, key);
  if (load.loaded) {
    cached.fields = std::move(load.fields);
    cached.from_cache = true;
    return cached;
  }
  cached.rebuilt_because = load.problem;
  cached.fields = precompute_separation_fields(bodies, interface, settings, &cached.report);
  save_separation_fields(file, key, cached.fields);
  return cached;
}

}  // namespace cohaptic
