#!/usr/bin/env bash
# `evtac import` on sessions of growing length: wall time, throughput and peak memory (RSS).
#
# The import cuts every trial in one pass over the session, chunk by chunk, checks the data
# table at the end of each full read in passes over it, reads the triggers in a pass that
# decodes nothing else and finds a log-free import's motions in a window of the gyroscope, so
# its memory should not grow with the session: this script checks that by importing sessions by
# their triggers and without a log, and prints one table row per run. The figures in
# docs/performance.md come from it.
#
# Usage (from the workspace root; needs GNU time):
#   crates/cli/benches/import_scale.sh [WORK_DIR [SESSION_DIR...]]
# Without SESSION_DIRs it simulates Experiment 1 sessions of 16 trials (tiny, about 1.7
# minutes) and 125 trials (small, about 16 minutes) into WORK_DIR. A SESSION_DIR is what
# `evtac simulate --session` writes. EVTAC=path/to/evtac runs that binary instead of building.
# MODES="trigger imu log-free" picks the imports (default: trigger log-free); `imu` reads the
# IMU in passes for `--sync imu`, which should not grow with the session either.
set -euo pipefail

work=${1:-target/import-scale}
shift || true
mkdir -p "$work"
if [ -z "${EVTAC:-}" ]; then
    cargo build --release --bin evtac >&2
    EVTAC=target/release/evtac
fi
sessions=("$@")
if [ ${#sessions[@]} -eq 0 ]; then
    for scale in tiny small; do
        if [ ! -f "$work/$scale/session.aedat4" ]; then
            "$EVTAC" simulate --session --protocol exp1 --scale "$scale" --seed 0 \
                --out "$work/$scale" >&2
        fi
        sessions+=("$work/$scale")
    done
fi

echo "| session | trials | session file | sync | wall s | events/s | MB/s | peak RSS MB |"
echo "|---|---|---|---|---|---|---|---|"
for session in "${sessions[@]}"; do
    name=$(basename "$session")
    bytes=$(stat -c %s "$session/session.aedat4")
    for mode in ${MODES:-trigger log-free}; do
        out="$work/$name-$mode"
        rm -rf "$out"
        args=(import "$session/session.aedat4" --out "$out"
            --calibration "$session/calibration.json")
        if [ "$mode" = trigger ] || [ "$mode" = imu ]; then
            args+=(--log "$session/robot_log.csv" --sync "$mode")
        else
            args+=(--depth-mm 2)
        fi
        # GNU time: elapsed seconds and the peak resident set in kB.
        /usr/bin/time -f "%e %M" -o "$work/time.txt" "$EVTAC" "${args[@]}" >"$work/stdout.txt"
        read -r wall rss_kb <"$work/time.txt"
        trials=$(($(wc -l <"$out/trials.csv") - 1))
        events=$(grep -o 'imported [0-9]* trials ([0-9]* events)' "$work/stdout.txt" |
            grep -o '([0-9]*' | tr -d '(')
        awk -v s="$name" -v n="$trials" -v b="$bytes" -v m="$mode" -v w="$wall" -v e="$events" \
            -v r="$rss_kb" 'BEGIN {
                printf "| %s | %d | %.0f MB | %s | %.2f | %.1f M | %.0f | %.0f |\n",
                    s, n, b / 1e6, m, w, e / w / 1e6, b / w / 1e6, r / 1024
            }'
        # Kept for comparing outputs between binaries (KEEP=1), else removed: a big session's
        # trials take gigabytes.
        [ -n "${KEEP:-}" ] || rm -rf "$out"
    done
done
