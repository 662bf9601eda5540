#!/usr/bin/env bash
# One entry point for the README's two commands:
#   bash workbench.sh demo   install what is missing, then run the main job on the default scene
#   bash workbench.sh test   install what is missing, then run the test suite
# Installing: Debian packages (Mesa EGL/llvmpipe, OSMesa, Xvfb, xwd, GLFW, POV-Ray) when missing, and
# a virtual environment .venv with the package and its test/bench/reference extras.  Safe to re-run.
set -euo pipefail
cd "$(dirname "$0")"
what="${1:-}"
case "$what" in demo|test) ;; *) echo "usage: bash workbench.sh demo|test" >&2; exit 2 ;; esac

debs=(libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6 xvfb xauth x11-apps libglfw3 povray)
missing=()
for d in "${debs[@]}"; do dpkg -s "$d" >/dev/null 2>&1 || missing+=("$d"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing Debian packages: ${missing[*]}"
  sudo_=""; [ "$(id -u)" -ne 0 ] && sudo_="sudo"
  $sudo_ apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_ apt-get install -y -qq "${missing[@]}" >/dev/null
fi

if [ ! -x .venv/bin/python ]; then
  echo "== creating .venv"
  python3 -m venv .venv
fi
stamp=.venv/.installed-$(sha1sum pyproject.toml | cut -c1-12)
if [ ! -f "$stamp" ]; then
  echo "== installing Python packages into .venv (first run takes a few minutes)"
  # (filtered out: pip's notes about this machine's unused local index folders, and setuptools'
  # "Editable installation" notice, which it prints for any editable install whose data folders
  # are mapped into the package, as shaders/ scenes/ stress/ examples/ are, to warn of a folder
  # named like the package in the working directory: here that folder is the package itself)
  { .venv/bin/python -m pip install -q --upgrade pip &&
    .venv/bin/python -m pip install -q -e '.[test,bench,reference]'; } 2>&1 | {
    grep -v -e 'is ignored: it is neither' -e 'BuildBackendWarning: Editable installation' \
            -e '^ *!! *$' -e '^ *[*]\{20,\} *$' -e 'Please be careful with folders in your working' \
            -e 'name as your package as they may take precedence' -e 'with strategy, WheelFile' -e '^ *$' || true; }
  rm -f .venv/.installed-*; touch "$stamp"
fi
export NUMBA_CACHE_DIR="$PWD/.numba_cache"

if [ "$what" = test ]; then
  # one test process per core, at most 4 (pytest-xdist); each takes whole test files, so a
  # file's fixtures and its scenes' compiled kernels stay in one process, handed out in the
  # order tests/conftest.py gives (PARALLEL_FIRST), not by their number of tests
  workers=$(nproc); [ "$workers" -gt 4 ] && workers=4
  echo "== running the test suite ($workers processes)"
  exec .venv/bin/python -m pytest -q -n "$workers" --dist loadfile --no-loadscope-reorder
fi

echo "== main job: quick error-vs-time study and side-by-side comparison of every method, on the default scene"
echo "   (whitted: point lights, judged against the Whitted ray tracer) and on cornell_spheres (an area light:"
echo "   every method applies, judged against the converged path tracer; its reference is cached after the first run)"
echo "   (the first run also compiles the numba kernels, a minute or two; later runs load them from .numba_cache)"
.venv/bin/workbench study whitted --quick --out out/report
.venv/bin/workbench compare whitted --out out/report
# (same size for both: the comparison reads the study's path-traced references back from the cache)
.venv/bin/workbench study cornell_spheres --quick --size 128x128 --methods phong,raycast,raytrace,radiosity,hybrid,pathtrace --out out/report_cornell_spheres
.venv/bin/workbench compare cornell_spheres --size 128x128 --out out/report_cornell_spheres
echo "== reports: $PWD/out/report/report.html and $PWD/out/report_cornell_spheres/report.html"
