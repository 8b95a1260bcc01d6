// The separation-forces paper's Fig. 10 drawn from a pull loop (pull_loop.h): (c) the
// force against the deflection through the phases AB, BC and CA, beside the threshold
// J_c l, and (b) the separated share of the held node's region against time. A command
// writes them with write_svg (common/study/svg_plot.h). Axes in mm, N and s.
#pragma once

#include "common/separation/pull_loop.h"
#include "common/study/svg_plot.h"

namespace cohaptic {

/// Series "AB", "BC", "CA" (each starting where the previous ended) and "J_c l".
LinePlot pull_loop_force_plot(const PullLoop& loop);

/// Series "A(R-bar)" (the held node's region) and "A(S-bar)" against time; `interface_area`
/// [m^2] normalises the separated area.
LinePlot pull_loop_area_plot(const PullLoop& loop, double interface_area);

}  // namespace cohaptic
