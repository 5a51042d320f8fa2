#!/usr/bin/env bash
# `evtac import` on sessions of growing length: wall time, throughput and peak memory (RSS).
#
# The import cuts every trial in one pass over the session, chunk by chunk, so its memory should
# not grow with the session (it still does, by the data table checked at the end of each full
# read: docs/performance.md): this script checks that by
# importing simulated sessions of 16 trials (tiny, about 1.7 minutes) and 125 trials (small,
# about 16 minutes) by their triggers and without a log, and prints one table row per run. The
# figures in docs/performance.md come from it.
#
# Usage: crates/cli/benches/import_scale.sh [WORK_DIR]   (from the workspace root; needs GNU time)
set -euo pipefail

work=${1:-target/import-scale}
mkdir -p "$work"
cargo build --release --bin evtac >&2
evtac=target/release/evtac

echo "| session | trials | session file | sync | wall s | events/s | MB/s | peak RSS MB |"
echo "|---|---|---|---|---|---|---|---|"
for scale in tiny small; do
    session="$work/$scale"
    if [ ! -f "$session/session.aedat4" ]; then
        "$evtac" simulate --session --protocol exp1 --scale "$scale" --seed 0 --out "$session" >&2
    fi
    bytes=$(stat -c %s "$session/session.aedat4")
    for mode in trigger log-free; do
        out="$work/$scale-$mode"
        rm -rf "$out"
        args=(import "$session/session.aedat4" --out "$out"
            --calibration "$session/calibration.json")
        if [ "$mode" = trigger ]; then
            args+=(--log "$session/robot_log.csv" --sync trigger)
        else
            args+=(--depth-mm 2)
        fi
        # GNU time: elapsed seconds and the peak resident set in kB.
        /usr/bin/time -f "%e %M" -o "$work/time.txt" "$evtac" "${args[@]}" >"$work/stdout.txt"
        read -r wall rss_kb <"$work/time.txt"
        trials=$(($(wc -l <"$out/trials.csv") - 1))
        events=$(grep -o 'imported [0-9]* trials ([0-9]* events)' "$work/stdout.txt" |
            grep -o '([0-9]*' | tr -d '(')
        awk -v s="$scale" -v n="$trials" -v b="$bytes" -v m="$mode" -v w="$wall" -v e="$events" \
            -v r="$rss_kb" 'BEGIN {
                printf "| %s | %d | %.0f MB | %s | %.2f | %.1f M | %.0f | %.0f |\n",
                    s, n, b / 1e6, m, w, e / w / 1e6, b / w / 1e6, r / 1024
            }'
    done
done
