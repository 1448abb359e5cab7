#!/usr/bin/env bash
# The long fuzz of the message decoders and the receive path (docs/transport.md "Fuzzing"):
# cvslam_fuzz_messages, built with AddressSanitizer and UndefinedBehaviorSanitizer, feeds
# COUNT random and mutated buffers per message type through the decoder and a subscription,
# unsigned and signed-then-tampered. Any sanitizer report aborts with a non-zero status.
#
#   scripts/fuzz_messages.sh [--count N (per type, default 1000000)] [--seed S] [--build DIR]
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build" ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --count|--seed) ARGS+=("$1" "${2:?$1 needs a value}"); shift 2 ;;
    --build) BUILD="${2:?--build needs a value}"; shift 2 ;;
    *) echo "fuzz_messages.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
cmake --build "$BUILD" --target cvslam_fuzz_messages -j2 >/dev/null
export ASAN_OPTIONS=abort_on_error=1:detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
start=$(date +%s)
"$BUILD/tests/cvslam_fuzz_messages" "${ARGS[@]}"
echo "fuzz_messages.sh: $(( $(date +%s) - start )) s, no sanitizer report"
