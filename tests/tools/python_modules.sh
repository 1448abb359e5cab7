# Sourced by the script tests that run the Python tools: sets PY to the interpreter — the
# system's /usr/bin/python3 (scripts/setup.sh installs numpy and matplotlib for it from Debian),
# else $PYTHON, else python3 — and exits 77 (ctest: skipped) when it lacks a module named.
#   source tests/tools/python_modules.sh TEST_NAME MODULE...
test_name="$1"
shift
PY=${PYTHON:-python3}
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3
for module in "$@"; do
  "$PY" -c "import $module" 2>/dev/null ||
    { echo "$test_name: needs python3 with $*: skipped"; exit 77; }
done
