#!/usr/bin/env bash
# The fastest caustica: `cargo build --release` optimised with pgo/caustica.profdata, a profile
# of the project's own renders (scripts/pgo/train.sh), so the hot paths are inlined and laid out
# as they run. The same code and the same images as the plain build. Extra arguments go to
# cargo. The Python package takes the profile the same way:
# RUSTFLAGS="-Cprofile-use=$PWD/pgo/caustica.profdata" pip install ./python
#
#   scripts/pgo/build.sh && target/release/caustica render
set -euo pipefail
cd "$(dirname "$0")/../.."
profile=$PWD/pgo/caustica.profdata
made_with=$(cat pgo/llvm-version)
have=$(rustc -vV | sed -n 's/^LLVM version: //p')
# An LLVM reads the profiles of its own and older versions only.
if [ "${have%%.*}" -lt "${made_with%%.*}" ]; then
    echo "note: this rustc's LLVM $have cannot read a profile made with LLVM $made_with; building without it" >&2
    exec cargo build --release "$@"
fi
# Functions changed since the profile was made are built as without it, silently.
RUSTFLAGS="${RUSTFLAGS:-} -Cprofile-use=$profile -Cllvm-args=-no-pgo-warn-mismatch" exec cargo build --release "$@"
