// On-disk cache of the precomputed separation fields, so a scene pays the FEM once.
//
// Keyed like the compliance cache: a BLAKE2b hash of both meshes, materials and supports,
// the interface (node pairs and triangles), the field settings (degree, samples, range,
// tool footprints) and the file-format version; the key is also the file name. The
// payload carries its own checksum: a truncated or corrupted file is reported and rebuilt.
// The fracture and laser settings are not in the key: they do not change the fields.
//
// Layout (little-endian, native doubles):
//   "CHSEPAR\0"  u32 format_version  key[32]  i32 degree  i32 node_count
//   i32 tool_node_count  u64 value_count  f64 values[value_count]
//   checksum[32] = BLAKE2b of every byte before it
#pragma once

#include <filesystem>
#include <string>

#include "common/separation/separation_fields.h"
#include "common/util/content_hash.h"

namespace cohaptic {

constexpr std::uint32_t kSeparationCacheFormatVersion = 1;

Digest separation_fields_key(const SeparationBodies& bodies, const SeparationInterface& interface,
                             const FieldSettings& settings);

/// The file for `key` inside `directory`.
std::filesystem::path separation_fields_file(const std::filesystem::path& directory,
                                             const Digest& key);

struct SeparationFieldsLoad {
  bool loaded = false;
  SeparationFields fields;
  std::string problem;  ///< why nothing was loaded ("no cache file", "checksum mismatch", ...)
};

/// The fields stored in `file` if it is a complete, uncorrupted cache for `key`; otherwise
/// says why. Never throws for a bad file.
SeparationFieldsLoad load_separation_fields(const std::filesystem::path& file, const Digest& key);

/// Writes atomically (temporary file, then rename). Throws Error naming the file.
void save_separation_fields(const std::filesystem::path& file, const Digest& key,
                            const SeparationFields& fields);

struct CachedSeparationFields {
  SeparationFields fields;
  bool from_cache = false;
  std::string rebuilt_because;   ///< the load problem when the fields were recomputed
  FieldPrecomputeReport report;  ///< zero when loaded
};

/// Loads the fields from `directory`, or precomputes and saves them there.
CachedSeparationFields cached_separation_fields(const std::filesystem::path& directory,
                                                const SeparationBodies& bodies,
                                                const SeparationInterface& interface,
                                                const FieldSettings& settings);

}  // namespace cohaptic
