#include "common/separation/pull_loop_figure.h"

#include <algorithm>

namespace cohaptic {

LinePlot pull_loop_force_plot(const PullLoop& loop) {
  LinePlot plot;
  plot.title = "Separation force against deflection (Fig. 10c)";
  plot.x_label = "deflection along the pull [mm]";
  plot.y_label = "force on the tissue [N]";
  plot.series = {Series{"AB", {}, {}, "#1f77b4", false}, Series{"BC", {}, {}, "#d62728", false},
                 Series{"CA", {}, {}, "#2ca02c", false}};
  double largest = 0;
  const PullLoopSample* previous = nullptr;
  for (const PullLoopSample& s : loop.samples) {
    Series& series = plot.series[s.phase == PullPhase::loading    ? 0
                                 : s.phase == PullPhase::fracture ? 1
                                                                  : 2];
    if (series.x.empty() && previous) {  // join the phases
      series.x.push_back(1e3 * previous->travel);
      series.y.push_back(previous->force);
    }
    series.x.push_back(1e3 * s.travel);
    series.y.push_back(s.force);
    largest = std::max(largest, s.travel);
    previous = &s;
  }
  plot.series.push_back(
      Series{"J_c l", {0.0, 1e3 * largest}, {loop.threshold, loop.threshold}, "#7f7f7f", false});
  return plot;
}

LinePlot pull_loop_area_plot(const PullLoop& loop, double interface_area) {
  LinePlot plot;
  plot.title = "Separated share against time (Fig. 10b)";
  plot.x_label = "time [s]";
  plot.y_label = "separated share";
  Series local{"A(R-bar) of the held node's region", {}, {}, "#d62728", false};
  Series global{"A(S-bar) of the interface", {}, {}, "#1f77b4", false};
  for (const PullLoopSample& s : loop.samples) {
    local.x.push_back(s.time);
    local.y.push_back(s.local_separated);
    global.x.push_back(s.time);
    global.y.push_back(s.separated_area / interface_area);
  }
  plot.series = {local, global};
  return plot;
}

}  // namespace cohaptic
