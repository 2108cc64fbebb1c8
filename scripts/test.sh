#!/usr/bin/env bash
# Installs what the tests need (idempotent) and runs every suite.
#
#   scripts/test.sh              apt (QGIS) + .venv + .venv-qgis, then ruff, mypy (core), core
#                                tests on both environments and the QGIS tests; closes with
#                                "N passed, N failed"
#   scripts/test.sh --core-env   only make sure the core environment .venv exists (make demo)
#
# Environments (see shared QGIS-ENV.md):
#   .venv       default python3 (pyenv or Debian), requirements-core.txt + `pip install -e .`
#   .venv-qgis  Debian's /usr/bin/python3 --system-site-packages (PyQGIS from apt), numpy pinned
#               to Debian's, requirements-qgis.txt + `pip install -e . --no-deps`
# Environment variables: PYTHON (interpreter for .venv, default python3), PYTEST_ARGS (extra).
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 2
ROOT=$PWD
MODE=${1:-all}
export DEBIAN_FRONTEND=noninteractive PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INPUT=1
export PIP_ROOT_USER_ACTION=ignore
# The adjustments solve normal equations of a few hundred unknowns: threaded BLAS only adds
# contention on a 2-core machine (measured: 50 s single-threaded vs 196 s threaded, loaded).
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
export LIDARPHOTO_REQUIRE_NUMBA=1  # tests/core/test_dda_backends.py must run, not skip
PYTHON=${PYTHON:-python3}
LOGDIR=$ROOT/.ci-logs
mkdir -p "$LOGDIR"
rm -f "$LOGDIR/summary.txt"

step() { printf '\n=== [%4ss] %s\n' "$SECONDS" "$*"; }
die() { echo "FATAL: $*" >&2; echo "0 passed, 1 failed" | tee "$LOGDIR/summary.txt"; exit 2; }

# ------------------------------------------------------------------------------ apt
apt_install() {  # installs the given Debian packages that are not installed yet
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  if ((${#missing[@]} == 0)); then return 0; fi
  step "apt-get install ${missing[*]}"
  local sudo=
  [ "$(id -u)" -eq 0 ] || sudo="sudo -n"
  local opts=(-o DPkg::Lock::Timeout=600 -o Dpkg::Use-Pty=0)
  local i
  for i in 1 2 3; do $sudo apt-get "${opts[@]}" update -qq && break; sleep 10; done
  $sudo apt-get "${opts[@]}" install -y -qq --no-install-recommends "${missing[@]}" \
    >"$LOGDIR/apt.log" 2>&1 || { tail -50 "$LOGDIR/apt.log"; die "apt-get install ${missing[*]}"; }
}

stamp_of() {  # a digest of the files and facts that decide an environment's content
  { cat "$@"; "$PY_FOR_STAMP" -V 2>&1; echo "${EXTRA_STAMP:-}"; } | sha256sum | cut -d' ' -f1
}

# ------------------------------------------------------------------------------ .venv (core)
ensure_core_env() {
  if ! "$PYTHON" -c 'import venv, ensurepip' 2>/dev/null; then
    apt_install python3-venv python3-pip
  fi
  local venv=$ROOT/.venv
  if ! "$venv/bin/python" -c 'import sys' 2>/dev/null; then
    step "create .venv ($("$PYTHON" -V 2>&1))"
    rm -rf "$venv"
    "$PYTHON" -m venv "$venv" || die "python3 -m venv .venv"
  fi
  PY_FOR_STAMP=$venv/bin/python EXTRA_STAMP= 
  local stamp
  stamp=$(stamp_of requirements-core.txt pyproject.toml)
  if [ "$(cat "$venv/.lidarphoto-stamp" 2>/dev/null)" != "$stamp" ]; then
    step ".venv: pip install -r requirements-core.txt -e ."
    "$venv/bin/python" -m pip install -q -r requirements-core.txt -e . || die "pip install (.venv)"
    echo "$stamp" >"$venv/.lidarphoto-stamp"
  else
    step ".venv up to date"
  fi
}

# ------------------------------------------------------------------------------ .venv-qgis
ensure_qgis_env() {
  apt_install qgis python3-qgis qgis-providers python3-venv python3-pip xvfb xauth
  # pylupdate5 and lrelease: tests/qgis/test_i18n.py extracts the strings and builds the .qm
  apt_install pyqt5-dev-tools qttools5-dev-tools
  local venv=$ROOT/.venv-qgis
  if ! "$venv/bin/python" -c 'import qgis.core' 2>/dev/null; then
    step "create .venv-qgis (/usr/bin/python3 --system-site-packages)"
    rm -rf "$venv"
    /usr/bin/python3 -m venv --system-site-packages "$venv" || die "venv .venv-qgis"
  fi
  local deb_numpy
  deb_numpy=$(/usr/bin/python3 -c 'import numpy; print(numpy.__version__)') || die "Debian numpy"
  printf 'numpy==%s\n' "$deb_numpy" >"$venv/constraints.txt"
  PY_FOR_STAMP=$venv/bin/python EXTRA_STAMP=$deb_numpy
  local stamp
  stamp=$(stamp_of requirements-qgis.txt pyproject.toml)
  if [ "$(cat "$venv/.lidarphoto-stamp" 2>/dev/null)" != "$stamp" ]; then
    step ".venv-qgis: pip install -c numpy==$deb_numpy -r requirements-qgis.txt; -e . --no-deps"
    "$venv/bin/python" -m pip install -q -c "$venv/constraints.txt" -r requirements-qgis.txt \
      || die "pip install (.venv-qgis)"
    "$venv/bin/python" -m pip install -q -c "$venv/constraints.txt" --no-deps -e . \
      || die "pip install -e . (.venv-qgis)"
    echo "$stamp" >"$venv/.lidarphoto-stamp"
  else
    step ".venv-qgis up to date"
  fi
  "$venv/bin/python" -c 'import numpy, osgeo.gdal_array; assert numpy.__version__.startswith("1.")' \
    || die "numpy in .venv-qgis is not ABI-compatible with Debian's GDAL/QGIS"
}

if [ "$MODE" = "--core-env" ]; then
  ensure_core_env
  exit 0
fi
[ "$MODE" = "all" ] || { echo "usage: $0 [--core-env]" >&2; exit 2; }

ensure_core_env
ensure_qgis_env

# ------------------------------------------------------------------------------ headless QGIS
export QT_QPA_PLATFORM=offscreen
export PROJ_DATA=/usr/share/proj  # Debian's pyproj inside a venv cannot find its data otherwise
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -w "${XDG_RUNTIME_DIR:-/nonexistent}" ]; then
  XDG_RUNTIME_DIR=$(mktemp -d)
  export XDG_RUNTIME_DIR
fi
chmod 700 "$XDG_RUNTIME_DIR" 2>/dev/null || true

NPASS=0 NFAIL=0 NSKIP=0 FAILED_SUITES=()

count_junit() {  # junit.xml -> "passed failed skipped"
  /usr/bin/python3 - "$1" <<'PY'
import sys
import xml.etree.ElementTree as ET
try:
    root = ET.parse(sys.argv[1]).getroot()
except Exception:
    print(0, 0, 0)
    raise SystemExit
suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
t = f = s = 0
for suite in suites:
    t += int(suite.get("tests", 0))
    f += int(suite.get("failures", 0)) + int(suite.get("errors", 0))
    s += int(suite.get("skipped", 0))
print(t - f - s, f, s)
PY
}

run_pytest() {  # name python pytest-args...   (exit 5 = no tests collected: not a failure)
  local name=$1 py=$2
  shift 2
  step "pytest: $name"
  local xml=$LOGDIR/junit-$name.xml
  rm -f "$xml"
  # shellcheck disable=SC2086
  timeout -k 30 1800 "$py" -m pytest "$@" -q -rfEs --junitxml="$xml" -o junit_family=xunit1 \
    ${PYTEST_ARGS:-}
  local rc=$?
  local p f s
  read -r p f s < <(count_junit "$xml")
  if [ "$rc" -eq 5 ]; then echo "($name: no tests collected)"; rc=0; fi
  if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi  # crashed before reporting
  NPASS=$((NPASS + p)) NFAIL=$((NFAIL + f)) NSKIP=$((NSKIP + s))
  if [ "$rc" -ne 0 ]; then FAILED_SUITES+=("$name(exit $rc)"); fi
}

step "ruff check"
if "$ROOT/.venv/bin/ruff" check .; then
  NPASS=$((NPASS + 1))
else
  NFAIL=$((NFAIL + 1)) FAILED_SUITES+=("ruff")
fi

# types of core: a new error fails (the modules that failed when the check came in are listed,
# with their counts, in pyproject.toml [tool.mypy]); about 30 s of CPU from a cold cache
step "mypy core"
if "$ROOT/.venv/bin/mypy" --cache-dir "$ROOT/.mypy_cache"; then
  NPASS=$((NPASS + 1))
else
  NFAIL=$((NFAIL + 1)) FAILED_SUITES+=("mypy")
fi

# tests/core plus every docstring example of the core (--doctest-modules)
run_pytest core "$ROOT/.venv/bin/python" tests/core core --doctest-modules
run_pytest core-numpy1 "$ROOT/.venv-qgis/bin/python" tests/core core --doctest-modules \
  -p no:pytest_qgis -p no:pytestqt
run_pytest qgis "$ROOT/.venv-qgis/bin/python" tests/qgis

step "done"
if ((${#FAILED_SUITES[@]})); then
  echo "failed: ${FAILED_SUITES[*]}"
fi
echo "$NPASS passed, $NFAIL failed, $NSKIP skipped" | tee "$LOGDIR/summary.txt"
((${#FAILED_SUITES[@]} == 0))
