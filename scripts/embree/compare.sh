#!/usr/bin/env bash
# Measures Embree (the `embreex` Python wheel's bundled library) on the `bvh` bench's meshes and
# incoherent and bounce rays, single-threaded, for the comparison in BENCHMARKS.md. Needs python3 and gcc;
# everything it installs stays in target/embree.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
work="$root/target/embree"
mkdir -p "$work"
if [ ! -x "$work/venv/bin/python" ]; then
    python3 -m venv "$work/venv"
    "$work/venv/bin/pip" install --quiet --no-deps embreex
fi
libs="$("$work/venv/bin/python" -c 'import embreex, os; print(os.path.join(os.path.dirname(os.path.dirname(embreex.__file__)), "embreex.libs"))')"
lib="$(ls "$libs"/libembree4*.so* | head -1)"
gcc -O2 -std=gnu11 -o "$work/embree_rays" "$root/scripts/embree/embree_rays.c" "$lib" -lm -Wl,-rpath,"$libs"
# The bench writes its rays (`BVH_BENCH_DUMP`) so both programs trace exactly the same ones; its
# filter matches no tracer, so it only builds the meshes and writes the rays.
(cd "$root" && BVH_BENCH_QUICK=1 BVH_BENCH_FILTER=dump-only BVH_BENCH_DUMP="$work" \
    cargo bench -p caustica-bench --bench bvh >/dev/null 2>&1)
for mesh in "sphere-37k 96 192 0" "bumpy-1M 500 1000 1"; do
    set -- $mesh
    for kind in incoherent bounce; do
        echo "$1 ($((2 * $2 * $3)) triangles), $kind rays:"
        "$work/embree_rays" "$2" "$3" "$4" "$work/$1-$kind.rays"
    done
done
