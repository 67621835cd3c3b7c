#!/usr/bin/env bash
# Fuzzes cloudprox: every reader, URDF, `collide` and the exact mesh queries
# (the targets of fuzz/, cargo-fuzz on the nightly toolchain).
#
# Usage: bash scripts/fuzz.sh [--smoke] [--runs N] [--time SECONDS] [TARGET...]
#   --runs N       executions per target (default 1000000)
#   --time S       wall-clock limit per target in seconds (default 3600)
#   --smoke        a short run: 20000 executions or 30 s per target
#   --max-len B    largest input of the file readers in bytes (default 65536,
#                  LAS/LAZ at most 10240; real seeds larger than this are left
#                  out); the structured targets (pointcloud2, collide, exact)
#                  take 4096, urdf and srdf 65536
#   --reuse-seeds  keep fuzz/seeds from an earlier run (no cargo test build)
#   --asan         build with the address sanitizer (about 3x slower; the
#                  default is no sanitizer: the code is safe Rust, and the
#                  targets abort on any single allocation above 512 MiB)
#   TARGET...      some of: ply pcd las stl obj off npy xyz pointcloud2 urdf srdf
#                  collide exact (default: all)
#
# Each target's corpus (fuzz/corpus/<target>, not committed) starts from seeds
# written by `cargo test --test fuzz_smoke -- --ignored write_seed_corpus`: small
# files made with cloudprox's writers, and the real files the Python tests fetch
# (<cache>/realfiles, $CLOUDPROX_CACHE or ~/.cache/cloudprox; files above 1 MiB
# are left out). Crashes go to fuzz/artifacts/<target>/; the executions each
# target reached are printed at the end (and kept in fuzz/last-run.txt).
# Requires: rustup's nightly toolchain and `cargo install cargo-fuzz`.
set -euo pipefail
cd "$(dirname "$0")/.."

runs=1000000
time_limit=3600
max_len=65536
reuse_seeds=0
sanitizer=none
targets=()
while [ $# -gt 0 ]; do
    case "$1" in
        --runs) runs="$2"; shift 2 ;;
        --time) time_limit="$2"; shift 2 ;;
        --smoke) runs=20000; time_limit=30; shift ;;
        --max-len) max_len="$2"; shift 2 ;;
        --reuse-seeds) reuse_seeds=1; shift ;;
        --asan) sanitizer=address; shift ;;
        -h|--help) sed -n '2,27p' "$0"; exit 0 ;;
        -*) echo "unknown option $1" >&2; exit 2 ;;
        *) targets+=("$1"); shift ;;
    esac
done
all=(ply pcd las stl obj off npy xyz pointcloud2 urdf srdf collide exact)
[ ${#targets[@]} -gt 0 ] || targets=("${all[@]}")

command -v cargo-fuzz >/dev/null || { echo "cargo-fuzz is missing: cargo install cargo-fuzz" >&2; exit 1; }

seeds="$PWD/fuzz/seeds"
if [ "$reuse_seeds" = 0 ] || [ ! -d "$seeds" ]; then
    echo "==> seeds"
    rm -rf "$seeds"
    CLOUDPROX_FUZZ_SEEDS="$seeds" cargo test -q -p cloudprox --test fuzz_smoke -- \
        --ignored --exact write_seed_corpus >/dev/null
fi

echo "==> build (nightly, sanitizer: $sanitizer, debug assertions)"
(cd fuzz && cargo +nightly fuzz build -s "$sanitizer")

report="$PWD/fuzz/last-run.txt"
: > "$report"
status=0
for t in "${targets[@]}"; do
    corpus="fuzz/corpus/$t"
    mkdir -p "$corpus"
    len=$max_len
    case "$t" in
        collide|exact|pointcloud2) len=4096 ;;
        urdf | srdf) len=65536 ;;
        # LAZ decoding is slow: 10 KiB keeps the small LAS 1.4 and LAZ seeds whole.
        las) len=$(( max_len < 10240 ? max_len : 10240 )) ;;
    esac
    find "$seeds/$t" -type f -size -$((len + 1))c -exec cp -n {} "$corpus/" \;
    echo "==> fuzz $t (runs $runs, at most ${time_limit}s, inputs up to $len bytes)"
    log="fuzz/$t.log"
    start=$(date +%s)
    if (cd fuzz && cargo +nightly fuzz run -s "$sanitizer" "$t" "corpus/$t" -- \
            -runs="$runs" -max_total_time="$time_limit" -max_len="$len" \
            -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 \
            -print_final_stats=1) >"$log" 2>&1; then
        result=ok
    else
        result=FAILED
        status=1
    fi
    secs=$(( $(date +%s) - start ))
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
    line="$t: $result, ${execs:-?} executions in ${secs}s (log $log)"
    echo "$line" | tee -a "$report"
    [ "$result" = ok ] || tail -40 "$log"
done
echo "==> summary"
cat "$report"
exit $status
