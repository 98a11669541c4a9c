#!/usr/bin/env bash
# The spread of timings over code layouts: builds the `spread` benchmark several times, each
# time with its functions placed by the linker in another order (LLD's
# `--shuffle-sections=*=SEED`; layout 0 is the default order), then runs every build in turns,
# twice, and prints each case's medians per layout (the better of its two runs) with their
# minimum, median and maximum, and the ratio forward dynamics / dense path per layout.
# Copies of one binary (`cargo bench -p mbs-benches --bench spread`) keep every function at
# its address; this changes the addresses.
#
#   benches/layout.sh [LAYOUTS]      (default 6: layout 0 and five shuffles)
#
# Needs the LLD linker Rust uses by default on x86-64 Linux (rust-lld); each build recompiles
# the benchmark crate only (about a minute on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
layouts=${1:-6}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bin() { ls -t target/release/deps/spread-* | grep -v '\.d$' | head -1; }
for k in $(seq 0 $((layouts - 1))); do
    if [ "$k" -eq 0 ]; then
        cargo rustc --quiet --release -p mbs-benches --bench spread
    else
        cargo rustc --quiet --release -p mbs-benches --bench spread -- \
            -C link-arg=-Wl,--shuffle-sections='*'="$k"
    fi
    cp "$(bin)" "$work/layout$k"
done
for round in 1 2; do
    for k in $(seq 0 $((layouts - 1))); do
        "$work/layout$k" --copy --bench | sed "s/^/$k\t$round\t/" >> "$work/runs"
    done
done
field() { grep -m1 "^$1[[:space:]]*:" /proc/cpuinfo | cut -d: -f2- | sed "s/^ *//"; }
echo "processor: $(field 'model name') (family $(field 'cpu family'), model $(field model))"
echo "ns per call, the better of two runs per layout (layouts 0..$((layouts - 1)), 0 the default order)"
awk -F'\t' -v L="$layouts" '
    { key = $3; v = $4 + 0
      if (!(key in seen)) { seen[key] = 1; order[++n] = key }
      if (!((key, $1) in best) || v < best[key, $1]) best[key, $1] = v }
    END {
      for (i = 1; i <= n; i++) {
        key = order[i]; line = sprintf("%-34s", key); m = 0
        for (k = 0; k < L; k++) {
          v = best[key, k]; line = line sprintf(" %7.0f", v)
          # insertion into the sorted x[1..m]
          for (j = ++m; j > 1 && x[j - 1] > v; j--) x[j] = x[j - 1]
          x[j] = v
        }
        printf "%s  min %.0f  median %.0f  max %.0f  max/min %.2f\n", line, x[1], x[int(m / 2) + 1], x[m], x[m] / x[1]
      }
      print "forward / dense per layout:"
      # every model of the cases: the names before " forward_dynamics"
      for (i = 1; i <= n; i++) {
        if (order[i] !~ / forward_dynamics$/) continue
        md = substr(order[i], 1, length(order[i]) - length(" forward_dynamics"))
        line = sprintf("%-34s", md)
        for (k = 0; k < L; k++)
          line = line sprintf(" %7.2f", best[md " forward_dynamics", k] / best[md " dense (M + h, Cholesky)", k])
        print line
      }
    }' "$work/runs"
