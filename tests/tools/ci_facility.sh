# Sourced by the script tests. `missing_facility TEST WHAT` ends a test whose host lacks a
# facility it needs (root, network namespaces, numpy, matplotlib): skipped (exit 77, ctest's
# SKIP_RETURN_CODE) on a developer's machine, failed (exit 1) under CI (CI=true), where
# scripts/setup.sh provides every facility and a skip would go unnoticed.
#   source tests/tools/ci_facility.sh; missing_facility netns_team "needs root"
missing_facility() {
  if [ "${CI:-}" = true ]; then
    echo "$1: $2: FAILED (CI=true: scripts/setup.sh provides this)" >&2
    exit 1
  fi
  echo "$1: $2: skipped"
  exit 77
}
