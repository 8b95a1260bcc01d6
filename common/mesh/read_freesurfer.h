// Reader for FreeSurfer ASCII surfaces (.asc, as written by mris_convert), e.g. the
// Colin27 brain and inner-skull surfaces under shared/data/colin27.
//
// Layout: line 1 a comment starting with '#'; line 2 "<vertices> <triangles>"; then one
// line per vertex "x y z flag"; then one line per triangle "i j k flag" with 0-based vertex
// indices (the trailing flag is optional and ignored). Coordinates are returned as in the
// file (FreeSurfer writes millimetres; the scene converts). Blank lines at the end are
// allowed; any other extra line is an error, since it means the header's counts are wrong.
// Every problem throws ParseError whose message starts "file:line:".
#pragma once

#include <filesystem>
#include <istream>
#include <string>

#include "common/mesh/triangle_surface.h"

namespace cohaptic {

/// Reads `path`. Throws Error if it cannot be opened, ParseError if it is malformed.
TriangleSurface read_freesurfer_ascii(const std::filesystem::path& path);

/// Parses FreeSurfer ASCII text; `source_name` starts every error message.
TriangleSurface parse_freesurfer_ascii(std::istream& in, const std::string& source_name);

}  // namespace cohaptic
