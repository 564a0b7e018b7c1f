#!/usr/bin/env bash
# Measures Embree (the `embreex` Python wheel's bundled library) on the `bvh` bench's meshes and
# incoherent rays, single-threaded, for the comparison in BENCHMARKS.md. Needs python3 and gcc;
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
echo "sphere-37k (2 x 96 x 192 triangles):"
"$work/embree_rays" 96 192 0
echo "bumpy-1M (2 x 500 x 1000 triangles):"
"$work/embree_rays" 500 1000 1
