#!/usr/bin/env bash
# Starts lcm-spy with cvslam's message types so it decodes our channels (docs/architecture.md).
# /usr/bin/lcm-spy cannot be used: it passes -Xincgc, which Java 17 rejects, and it does
# not put our type jar on the class path.
#
#   scripts/lcm-spy.sh [--lcm-url URL] [--build-dir DIR]   start the spy (needs an X display;
#                                                         use xvfb-run without one)
#   scripts/lcm-spy.sh --check [--build-dir DIR]          check the jars, print the class path
#   scripts/lcm-spy.sh --help
#
# URL defaults to $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0. The Java receiver
# ignores recv_buf_size: for image channels raise net.core.rmem_default (scripts/setup.sh).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
url=${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0}
build_dir=$root/build
check_only=false
java_dir=${CVSLAM_JAVA_DIR:-/usr/share/java}

die() { echo "lcm-spy.sh: $*" >&2; exit 1; }

while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --check) check_only=true ;;
    --lcm-url|-l) [ $# -ge 2 ] || die "$1 needs a value"; url=$2; shift ;;
    --lcm-url=*) url=${1#--lcm-url=} ;;
    --build-dir) [ $# -ge 2 ] || die "$1 needs a value"; build_dir=$2; shift ;;
    --build-dir=*) build_dir=${1#--build-dir=} ;;
    *) echo "lcm-spy.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done

types_jar=$build_dir/cvslam_lcmtypes.jar
lcm_jar=$java_dir/lcm.jar
chart_jar=$java_dir/jchart2d.jar

command -v java >/dev/null || die "java not found (apt-get install default-jdk-headless)"
[ -f "$lcm_jar" ] || die "$lcm_jar not found (apt-get install liblcm-java)"
[ -f "$chart_jar" ] || die "$chart_jar not found (apt-get install libjchart2d-java)"
[ -f "$types_jar" ] || die "$types_jar not found: build it with" \
  "'cmake --build $build_dir --target cvslam_lcmtypes_jar' (needs a JDK at configure time)"

classpath=$lcm_jar:$types_jar:$chart_jar
if $check_only; then
  echo "$classpath"
  exit 0
fi
[ -n "${DISPLAY:-}" ] || die "no X display: set DISPLAY, or run under xvfb-run"

exec java -Djava.net.preferIPv4Stack=true -Xmx512m -cp "$classpath" lcm.spy.Spy \
  --lcm-url="$url"
