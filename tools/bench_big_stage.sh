#!/bin/sh
# The big-stage figures of BENCHMARKS.md ("Big stages", issue 24 item 5): wall time and peak RSS
# of `luxeval lights` and `luxeval emission` (16 directions, --device cpu) on stages of N plain
# SphereLights (tools/gen_big_stage.py), for one or more luxeval binaries run alternately, so
# that a machine whose load drifts affects each alike. Needs GNU time (/usr/bin/time) and
# NumPy (for the directions).
#
#   tools/bench_big_stage.sh OUT_DIR "10000 30000 100000" RUNS BIN [BIN ...]
#
# GROUP=K (default 4) puts K lights under each Xform; GROUP=all puts every light under /World
# (N siblings under one prim).
#
# Prints one tab-separated row per run: N, lights per Xform, command, binary, wall s, user + sys
# s, peak RSS MiB.
set -eu
out=$1
sizes=$2
runs=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
python3 -c "import numpy as np; np.save('$out/dirs16.npy', np.random.default_rng(1).normal(size=(16, 3)).astype('<f4'))"
group=${GROUP:-4}
stage() {
    echo "$out/s$1_g$group.usda"
}
for n in $sizes; do
    k=$group
    [ "$k" = all ] && k=$n
    [ -f "$(stage "$n")" ] || python3 "$here/gen_big_stage.py" "$n" "$(stage "$n")" --per-group "$k"
done
printf 'N\tgroup\tcommand\tbinary\twall_s\tcpu_s\tpeak_rss_MiB\n'
for n in $sizes; do
    for cmd in lights emission; do
        r=1
        while [ "$r" -le "$runs" ]; do
            for bin in "$@"; do
                case $cmd in
                    lights) args="lights $(stage "$n")" ;;
                    emission) args="emission $(stage "$n") --dirs $out/dirs16.npy -o $out/e.npy --device cpu" ;;
                esac
                # shellcheck disable=SC2086 # args is split on purpose
                /usr/bin/time -f '%e %U %S %M' -o "$out/time.txt" "$bin" $args >/dev/null 2>"$out/stderr.txt" || {
                    echo "failed: $bin $args" >&2
                    cat "$out/stderr.txt" >&2
                    exit 1
                }
                awk -v n="$n" -v g="$group" -v c="$cmd" -v b="$bin" \
                    '{ printf "%s\t%s\t%s\t%s\t%s\t%.2f\t%d\n", n, g, c, b, $1, $2 + $3, $4 / 1024 }' \
                    "$out/time.txt"
            done
            r=$((r + 1))
        done
    done
done
