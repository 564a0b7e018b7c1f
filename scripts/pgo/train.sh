#!/usr/bin/env bash
# Makes pgo/caustica.profdata, the profile scripts/pgo/build.sh optimises with: builds caustica
# instrumented, renders the project's own scenes with it (every integrator, every reader, a
# large mesh's build and walks), and merges the counts. Run it after changes to the hot paths: a
# stale profile leaves the changed functions unguided, and code it never ran is built as cold.
# Needs the toolchain's llvm-profdata (`rustup component add llvm-tools`).
#
#   scripts/pgo/train.sh            # about 6 minutes on 2 cores
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
work=target/pgo-train
profdata=$(find "$(rustc --print sysroot)" -name llvm-profdata -type f | head -1)
[ -x "$profdata" ] || { echo "no llvm-profdata: rustup component add llvm-tools" >&2; exit 2; }

rm -rf "$work/raw" "$work/out"
mkdir -p "$work/raw" "$work/out"
# The instrumented build, apart from the release one and without the profile it replaces.
RUSTFLAGS="-Cprofile-generate=$repo/$work/raw" \
    cargo build --release -p caustica-cli --target-dir "$work/target"
bin=$work/target/release/caustica

log=$work/renders.log
: >"$log"
render() { "$bin" render "$@" --seed 1 --threads 2 >/dev/null 2>>"$log" || { tail -3 "$log" >&2; exit 1; }; }

# The project's scenes with their own integrators (a course scene's Whitted tracer and photon
# map), then with path and vcm.
for scene in scenes/*.ray scenes/*.pbrt; do
    name=$(basename "$scene")
    case $scene in
        *.ray) render "$scene" --width 96 -o "$work/out/$name.exr" ;;
        *) render "$scene" --width 96 --passes 4 -o "$work/out/$name.exr" ;;
    esac
    for integrator in path vcm; do
        render "$scene" --model physical --integrator "$integrator" --width 96 --passes 8 -o "$work/out/$name-$integrator.exr"
    done
done
render scenes/mirror_box.ray --model physical --integrator lt --width 96 --passes 8 -o "$work/out/lt.exr"
render scenes/ring.ray --model physical --integrator gi --width 64 --passes 2 -o "$work/out/gi.exr"
render --width 128 -o "$work/out/default.png"

# training_scenes.py's: lamp-lit glass and metal balls, a glass mesh within the caches and a
# ball of 500,000 triangles beyond them, rough metal plates under four lamps, a textured glTF
# and an OBJ with its MTL.
python3 scripts/pgo/training_scenes.py "$work/scenes"
for scene in "$work"/scenes/*.gltf "$work"/scenes/*.obj "$work"/scenes/*.pbrt; do
    name=$(basename "$scene")
    render "$scene" --model physical --integrator path --width 128 --passes 64 -o "$work/out/$name-path.exr"
    render "$scene" --model physical --integrator vcm --width 96 --passes 8 -o "$work/out/$name-vcm.exr"
done
# Camera paths in a box of walls as much as the light-side integrators' photons.
render scenes/mirror_box.ray --model physical --integrator path --width 128 --passes 64 -o "$work/out/box-path.exr"

mkdir -p pgo
"$profdata" merge --sparse -o pgo/caustica.profdata "$work"/raw/*.profraw
rustc -vV | sed -n 's/^LLVM version: //p' > pgo/llvm-version
echo "pgo/caustica.profdata: $(du -h pgo/caustica.profdata | cut -f1), LLVM $(cat pgo/llvm-version)"
