#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# Cold views with reading ahead on and off, interleaved (docs/notes/performance-notebook.md,
# parts 13 and 21). Needs root for drop_caches; writes its files to /tmp/pf/r. MODES (default
# "on off") lists the --prefetch values compared, taken in turn, the order rotating from run to
# run.
# usage: [MODES="on off always"] tools/bench/bench_prefetch.sh BUILD RUNS FILE.ibv...
B=$1; RUNS=$2; shift 2
read -r -a modes <<<"${MODES:-on off}"

mkdir -p /tmp/pf/r
for f in "$@"; do
  for i in $(seq 1 $RUNS); do
    n=${#modes[@]}
    order=""
    for k in $(seq 0 $((n - 1))); do order="$order ${modes[$(((i + k) % n))]}"; done
    for pf in $order; do
      sync; echo 3 > /proc/sys/vm/drop_caches
      tag=$(basename $f .ibv)_${pf}_$i
      $B/isorender $f --iso 600.5 --view -y --software --cache-mb 512 --prefetch $pf \
        --progress /tmp/pf/r/p_$tag.csv --stats /tmp/pf/r/s_$tag.json -o /tmp/pf/r/i_$tag.png --force -q > /dev/null
      python3 - /tmp/pf/r/p_$tag.csv /tmp/pf/r/s_$tag.json $tag <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def t(p):
    for r in rows:
        if float(r['final_pixel_pct']) >= p: return float(r['time_s'])
s = json.load(open(sys.argv[2])); c = s['cache']
print(sys.argv[3], "%.3f %.3f %.3f" % (t(85), t(99.5), s['time']['extraction_wall_s']),
      "wait %.3f decode %.3f misses %d prefetched %d hits %d disk %.1f MiB load %s" % (
      c['wait_seconds'], c['decode_seconds'], c['misses'], c['prefetched'], c['prefetch_hits'],
      c['bytes_read_disk'] / 2**20, open('/proc/loadavg').read().split()[0]))
PY
    done
  done
done
