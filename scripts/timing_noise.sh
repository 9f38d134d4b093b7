#!/usr/bin/env bash
# How far `harness bench`'s pass/floor ratios move on an unchanged build: N quiet runs, N runs
# beside a busy neighbour (`yes > /dev/null` on one core), N/2 runs with LP_NUM_THREADS=1, then
# a table per scene, backend and pass (docs/2026-11-25-timing-noise.md was made with N = 8).
# Nothing else should run meanwhile. Needs python3.
#
#   scripts/timing_noise.sh [N] [FRAMES]   (default 8 runs of 5 frames; about 4 minutes at 8 on
#                                           a 2-core machine, 4 times that at 21 frames)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-8}
frames=${2:-5}
dir=$(mktemp -d)
cargo build -q -p harness --bin harness
bin=target/debug/harness
for i in $(seq "$n"); do "$bin" bench --frames "$frames" --json --out "$dir/out" > "$dir/quiet_$i.json" 2>/dev/null; done
for i in $(seq "$n"); do
  yes > /dev/null & busy=$!
  "$bin" bench --frames "$frames" --json --out "$dir/out" > "$dir/busy_$i.json" 2>/dev/null
  kill "$busy"
done
for i in $(seq $(( (n + 1) / 2 ))); do
  LP_NUM_THREADS=1 "$bin" bench --frames "$frames" --json --out "$dir/out" > "$dir/threads1_$i.json" 2>/dev/null
done
python3 - "$dir" <<'PY'
import glob, json, statistics, sys
dir = sys.argv[1]
def runs(condition):
    out = []
    for path in sorted(glob.glob(f"{dir}/{condition}_*.json")):
        ratios = {}
        for scene in json.load(open(path))["scenes"]:
            for p in scene["passes"]:
                if p["ratio"] is not None:
                    ratios[(scene["scene"], scene["backend"], p["pass"])] = (p["ratio"], p["median_ms"])
        out.append(ratios)
    return out
quiet, busy, threads1 = runs("quiet"), runs("busy"), runs("threads1")
print(f"{'scene':7} {'backend':11} {'pass':22} {'ms':>6} {'quiet ratio min..max (spread)':>32} "
      f"{'busy spread vs quiet median':>28} {'threads1 vs quiet median':>26}")
for key in sorted(set().union(*map(set, quiet))):
    q = [r[key][0] for r in quiet if key in r]
    ms = statistics.median([r[key][1] for r in quiet if key in r])
    median = statistics.median(q)
    def band(rows):
        values = [r[key][0] / median for r in rows if key in r]
        return (min(values), max(values)) if values else (0.0, 0.0)
    b, t = band(busy), band(threads1)
    print(f"{key[0]:7} {key[1]:11} {key[2]:22} {ms:6.2f} {min(q):7.2f}..{max(q):7.2f} "
          f"(x{max(q) / min(q):5.2f})        {b[0]:5.2f}..{b[1]:5.2f}            {t[0]:5.2f}..{t[1]:5.2f}")
PY
rm -rf "$dir"
