// On-disk cache of compliance columns, so a scene's precomputation is paid once.
//
// A cache file is valid only for the exact mesh, material, boundary conditions, row
// nodes, route (solves or the Schur complement: their columns differ in the last bits) and
// file-format version it was computed for: all of them go into its key (a
// BLAKE2b content hash), which is also the file name. The payload carries its own
// checksum, so a truncated or corrupted file is detected and the caller rebuilds it.
//
// Layout (little-endian, native doubles):
//   "CHCOMPL\0"  u32 format_version  key[32]  u32 row_count  i32 row_nodes[row_count]
//   u32 column_count  { i32 node  f64 values[3*row_count*3] (column-major) } * column_count
//   checksum[32] = BLAKE2b of every byte before it
#pragma once

#include <filesystem>
#include <string>

#include "common/fem/compliance.h"
#include "common/fem/linear_elastic_material.h"
#include "common/mesh/tet_mesh.h"
#include "common/util/content_hash.h"
#include "common/util/progress_log.h"

namespace cohaptic {

// 2: columns solved in fixed groups; 3: groups of 4 (a column's bits depend on its group's
// size); 4: the route in the key; 5: the Schur route's interior order and dense inverse
// (its bits)
constexpr std::uint32_t kComplianceCacheFormatVersion = 5;

/// How the columns were computed: solves in fixed groups (ComplianceColumns), or every row
/// node's at once by the Schur complement (schur_compliance.h).
enum class ComplianceRoute : int { solves = 0, schur = 1 };

Digest compliance_cache_key(const TetMesh& mesh, const LinearElasticMaterial& material,
                            const DofMap& dofs, const std::vector<int>& row_nodes,
                            ComplianceRoute route);

/// The file for `key` inside `directory`.
std::filesystem::path compliance_cache_file(const std::filesystem::path& directory,
                                            const Digest& key);

struct ComplianceCacheLoad {
  bool loaded = false;
  int columns = 0;      ///< columns inserted
  std::string problem;  ///< why nothing was loaded ("no cache file", "checksum mismatch", ...)
};

/// Inserts the cached columns into `columns` if `file` is a complete, uncorrupted cache for
/// `key`; otherwise leaves `columns` untouched and says why. Never throws for a bad file.
/// `progress`, if given, counts the columns read.
ComplianceCacheLoad load_compliance_cache(const std::filesystem::path& file, const Digest& key,
                                          ComplianceColumns& columns,
                                          ProgressLog* progress = nullptr);

/// Writes every cached column, atomically (temporary file, then rename). Throws Error
/// naming the file and the reason (e.g. a full disk); an existing cache is left intact.
/// `progress`, if given, counts the columns written, then shows the sync to disk.
void save_compliance_cache(const std::filesystem::path& file, const Digest& key,
                           const ComplianceColumns& columns, ProgressLog* progress = nullptr);

}  // namespace cohaptic
