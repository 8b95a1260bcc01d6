#!/usr/bin/env bash
# The paper's first two experiments as paired comparisons rated by simulated subjects
# (scenes/studies/experiment1_paired.yaml, experiment2_paired.yaml: trials with the real
# programs, then ten simulated subjects rating every pair, then Scheffe's analysis), printed
# as the Markdown page docs/results/paired-comparisons.md holds; each experiment's scale-line
# figure is copied to docs/results/paired-comparisons/. The studies run in out/paired/
# (about 2.5 minutes each; run again, a finished study is not run again).
#
# Usage: tests/paired_rehearsal_page.sh [path/to/cohaptic-lab]   (make paired-rehearsal runs it)
set -euo pipefail
cd "$(dirname "$0")/.."
lab=${1:-build/lab/cohaptic-lab}
[[ -x "$lab" ]] || { echo "paired_rehearsal_page: no cohaptic-lab at $lab (build it: make build)" >&2; exit 2; }
figures=docs/results/paired-comparisons
mkdir -p "$figures"
for n in 1 2; do
  "$lab" study "scenes/studies/experiment${n}_paired.yaml" --out "out/paired/experiment$n" >&2
  cp "out/paired/experiment$n/figures/scale.svg" "$figures/experiment$n.svg"
done

cat <<'HEADER'
# Paired comparisons rehearsed with simulated subjects

`make paired-rehearsal > docs/results/paired-comparisons.md` writes this page
(`tests/paired_rehearsal_page.sh`). Each study measures every condition twice with the hand
model pressing the paper's cube (real `cohaptic-server` and `cohaptic-client` processes),
then ten simulated subjects rate every pair once on five grades from the two conditions'
measures (`common/study/simulated_rater.h`: the force update rate for "finer", the terminal
force ratio for "harder", a just-noticeable difference and noise of their own), and
Scheffé's method in Nakaya's modification gives each condition's scale value, the analysis
of variance and the yardsticks (docs/studies.md "Paired comparisons (Scheffé's method, Nakaya's modification)"). Two scale values
further apart than Y(0.05) differ at the 5 % level.

HEADER
for n in 1 2; do
  case $n in
    1) echo "## Experiment 1: which felt finer? (S0 × {T0, T150, T300} × {P0, P1})" ;;
    2) echo "## Experiment 2: which felt harder? ({S0, S30, S100} × {T0, T150} × P0)" ;;
  esac
  echo
  echo "![scale line](paired-comparisons/experiment$n.svg)"
  echo
  echo '```'
  cat "out/paired/experiment$n/analysis/table.txt"
  echo '```'
  echo
done
tests/results_stamp.sh
