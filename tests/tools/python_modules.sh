# Sourced by the script tests that run the Python tools: sets PY to the interpreter — the
# system's /usr/bin/python3 (scripts/setup.sh installs numpy and matplotlib for it from Debian),
# else $PYTHON, else python3 — and ends the test when it lacks a module named (skipped, or
# failed under CI=true: tests/tools/ci_facility.sh).
#   source tests/tools/python_modules.sh TEST_NAME MODULE...
source "$(dirname "${BASH_SOURCE[0]}")/ci_facility.sh"
test_name="$1"
shift
PY=${PYTHON:-python3}
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3
for module in "$@"; do
  "$PY" -c "import $module" 2>/dev/null ||
    missing_facility "$test_name" "$PY lacks the python module $module (needs $*)"
done
