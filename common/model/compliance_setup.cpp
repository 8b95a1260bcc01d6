#include "common/model/compliance_setup.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>

#include "common/fem/compliance_disk_cache.h"
#include "common/fem/schur_compliance.h"
#include "common/mesh/compact_groups.h"
#include "common/util/blas_threads.h"
#include "common/util/error.h"
#include "common/util/progress_log.h"
#include "common/util/stopwatch.h"

namespace cohaptic {

std::vector<int> compliance_row_nodes(const ElasticBody& body, bool whole_surface) {
  return order_in_compact_groups(body.mesh.nodes,
                                 whole_surface ? body.surface.nodes : body.touchable_nodes,
                                 ComplianceColumns::kGroupSize);
}

std::filesystem::path default_cache_directory() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "cohaptic";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "cohaptic";
  return ".cohaptic-cache";
}

namespace {

// Precomputed touchable columns that are at least half of the row nodes come by the Schur
// complement (every row node's at once, BLAS on kFactorBlasThreads threads); any others by solves.
ComplianceRoute route_of(const ElasticBody& body, const ComplianceColumns& columns) {
  return body.spec.compliance.precompute_touchable &&
                 2 * body.touchable_nodes.size() >= columns.row_nodes().size()
             ? ComplianceRoute::schur
             : ComplianceRoute::solves;
}

Digest cache_key(const ElasticBody& body, const ComplianceColumns& columns) {
  return compliance_cache_key(body.mesh, body.spec.material, body.dofs, columns.row_nodes(),
                              route_of(body, columns));
}

void precompute_touchable_columns(const ElasticBody& body, ComplianceColumns& columns,
                                  ProgressLog& progress) {
  std::size_t missing = 0;
  for (int node : body.touchable_nodes) missing += columns.has_column(node) ? 0 : 1;
  if (missing == 0) return;
  if (route_of(body, columns) == ComplianceRoute::solves) {
    progress.set_phase(fmt::format("solving for {} nodes' columns", missing));
    columns.compute_columns(body.touchable_nodes);
    return;
  }
  spdlog::info(
      "compliance: {} row nodes at once (Schur complement, BLAS on {} threads, OpenBLAS's {} "
      "kernels)",
      columns.row_nodes().size(), kFactorBlasThreads, blas_kernels());
  compute_row_columns_by_schur(columns, restrict_to_dofs(body.stiffness, body.dofs.free_dofs),
                               body.dofs, &progress);
}

}  // namespace

ComplianceSetup prepare_compliance(const ElasticBody& body, ComplianceColumns& columns,
                                   const std::optional<std::filesystem::path>& cache_directory) {
  ComplianceSetup setup;
  Stopwatch watch;
  ProgressLog progress("compliance");
  const bool use_disk = cache_directory.has_value() && body.spec.compliance.disk_cache;
  if (use_disk) {
    const Digest key = cache_key(body, columns);
    setup.cache_file = compliance_cache_file(*cache_directory, key);
    progress.set_phase("loading " + setup.cache_file.string());
    const ComplianceCacheLoad load =
        load_compliance_cache(setup.cache_file, key, columns, &progress);
    setup.from_disk = load.loaded;
    setup.note = load.loaded ? fmt::format("loaded {} columns from {}", load.columns,
                                           setup.cache_file.string())
                             : fmt::format("cache {}: {}", setup.cache_file.string(), load.problem);
    if (!load.loaded && load.problem != "no cache file")
      spdlog::warn("compliance {}; rebuilding it", setup.note);
  }
  const bool want_all = body.spec.compliance.precompute_touchable;
  const std::size_t before = columns.column_count();
  if (want_all) precompute_touchable_columns(body, columns, progress);
  // K_ff's factor solves any row's column that is still missing, on demand: factored here,
  // before the session, rather than at a first touch. With every row's column cached or
  // made by the Schur complement, it is never needed.
  const auto& rows = columns.row_nodes();
  if (!std::all_of(rows.begin(), rows.end(), [&](int node) { return columns.has_column(node); })) {
    progress.set_phase("factoring the stiffness matrix");
    body.free_factor.factor(&progress);
  }
  if (use_disk && columns.column_count() > before) {
    progress.set_phase("saving the columns to " + setup.cache_file.string());
    save_compliance(body, columns, *cache_directory, &progress);
    setup.note +=
        fmt::format("; computed {} columns and saved them", columns.column_count() - before);
  }
  setup.columns = columns.column_count();
  setup.ms = watch.elapsed_ms();
  spdlog::info("compliance: {} columns of {} rows ready in {:.1f} ms{}", setup.columns,
               3 * columns.row_nodes().size(), setup.ms,
               setup.note.empty() ? "" : " (" + setup.note + ")");
  return setup;
}

void save_compliance(const ElasticBody& body, const ComplianceColumns& columns,
                     const std::filesystem::path& cache_directory, ProgressLog* progress) {
  const Digest key = cache_key(body, columns);
  try {
    save_compliance_cache(compliance_cache_file(cache_directory, key), key, columns, progress);
  } catch (const Error& e) {
    spdlog::warn("compliance cache not saved (the results are unaffected): {}", e.what());
  }
}

}  // namespace cohaptic
