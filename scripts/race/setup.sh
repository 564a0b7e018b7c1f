#!/usr/bin/env bash
# Installs what scripts/race needs; safe to run again. A Python venv (default target/race-venv)
# with Mitsuba 3.9.1 and Dr.Jit 1.5.0 (the versions the reference images were made and the race
# was checked with), NumPy and Matplotlib; and Debian's libllvm19 for Mitsuba's llvm_ad_rgb
# variant, installed with apt-get when it is missing and apt is there. Ends with a one-core render.
#   usage: scripts/race/setup.sh [VENV_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
venv=${1:-$root/target/race-venv}
llvm=${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1}

if [ ! -e "$llvm" ]; then
  if command -v apt-get >/dev/null; then
    sudo=$([ "$(id -u)" = 0 ] || echo sudo)
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq libllvm19
    [ -e "$llvm" ] || llvm=$(dpkg -L libllvm19 | grep -E '/libLLVM\.so\.19(\.[0-9]+)*$' | head -1)
  fi
  [ -e "$llvm" ] || { echo "LLVM 19 not found: install libllvm19 or set DRJIT_LIBLLVM_PATH" >&2; exit 1; }
fi
export DRJIT_LIBLLVM_PATH=$llvm

[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q 'mitsuba==3.9.1' 'drjit==1.5.0' numpy matplotlib

# check: the llvm variant renders on one thread, and an EXR can be written afterwards
"$venv/bin/python" - <<'PY'
import os, tempfile
import mitsuba as mi, drjit as dr, numpy, matplotlib
mi.set_variant('llvm_ad_rgb')
dr.set_thread_count(1)
img = mi.render(mi.load_dict(mi.cornell_box()), spp=1)
dr.set_thread_count(2)   # EXR writing deadlocks with an empty pool
mi.Bitmap(img).write(os.path.join(tempfile.mkdtemp(), 'check.exr'))
print(f'ok: mitsuba {mi.__version__}, drjit {dr.__version__}, numpy {numpy.__version__}, '
      f'matplotlib {matplotlib.__version__}, llvm_ad_rgb renders on one thread')
PY
echo "export DRJIT_LIBLLVM_PATH=$llvm   # the race scripts set this themselves when it is unset"
echo "venv: $venv (race.py, throughput.py and report.py switch to it by themselves)"
