// Fuzz target: the FreeSurfer ASCII surface reader (common/mesh/read_freesurfer.h), as a
// scene's obstacle is read, followed by the surface check an obstacle gets.
//
// Input: the text of an .asc file. Properties:
//   - parse_freesurfer_ascii() and check_triangle_surface() either accept or throw
//     cohaptic::Error (ParseError): nothing else escapes;
//   - a surface read has finite coordinates and every triangle's vertices in range.
#include <cstdint>
#include <sstream>
#include <string>

#include "common/mesh/mesh_checks.h"
#include "common/mesh/read_freesurfer.h"
#include "common/util/error.h"
#include "tests/fuzz/fuzz_support.h"

using namespace cohaptic;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const TriangleSurface surface = parse_freesurfer_ascii(in, "fuzz.asc");
    fuzz::require(surface.vertices.allFinite(), "vertex coordinates are finite");
    for (const Triangle& triangle : surface.triangles)
      for (int vertex : triangle)
        fuzz::require(vertex >= 0 && vertex < surface.vertex_count(),
                      "triangle vertices are in range");
    check_triangle_surface(surface, "fuzz.asc");
  } catch (const Error&) {
  }
  return 0;
}
