#!/usr/bin/env bash
# Starts lcm-spy so that it decodes vimot's message types.
#
# How lcm-spy finds types: Debian's /usr/bin/lcm-spy runs
#   java -Xincgc ... -cp /usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar lcm.spy.Spy
# Its type scan (lcm.util.ClassDiscoverer) reads the CLASSPATH environment
# variable in addition to -cp and loads the classes it finds there through
# its own class loader, so the vimot jar goes into CLASSPATH and the
# launcher stays as installed. Java 17 refuses the long-removed -Xincgc
# unless told to ignore unknown VM options (JDK_JAVA_OPTIONS).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIMOT_BUILD_DIR:-$here/build}"
jar="$build/lcmtypes/vimot_lcmtypes.jar"
jchart2d="/usr/share/java/jchart2d.jar"
me="$(basename "$0")"

usage() {
  cat <<EOF
Usage: $me [lcm-spy options...]

Starts lcm-spy with the vimot LCM types on its CLASSPATH, so every vimot
channel is decoded. All options are passed to lcm-spy:
  -l, --lcm-url=URL   LCM URL to listen on, e.g.
                        $me --lcm-url='udpm://239.255.76.67:7667?ttl=0'
                        $me --lcm-url='file:///path/to/run.lcmlog?speed=1'  (replay a log)

Jar: \${VIMOT_BUILD_DIR:-<repo>/build}/lcmtypes/vimot_lcmtypes.jar
     (now: $jar)
If the build directory is configured, the jar is first brought up to date
(cmake --build --target vimot_lcmtypes_jar), so lcm-spy never runs with
types older than the .lcm files; if it is missing, the project is
configured and the jar built.

Environment: VIMOT_BUILD_DIR (build directory), LCM_DEFAULT_URL (LCM's own
default URL), CLASSPATH (kept, after the vimot jar).
EOF
}

die() {
  echo "$me: $*" >&2
  exit 1
}

for arg in "$@"; do
  case "$arg" in
    -h | --help) usage; exit 0 ;;
  esac
done

# ---- the jar ---------------------------------------------------------------
if command -v cmake >/dev/null 2>&1; then
  if [ ! -f "$build/CMakeCache.txt" ] && [ ! -f "$jar" ]; then
    echo "$me: $jar not found; configuring $build" >&2
    cmake -S "$here" -B "$build" >&2 ||
      die "configuring $build failed; cannot build $jar"
  fi
  if [ -f "$build/CMakeCache.txt" ]; then
    [ -f "$jar" ] || echo "$me: building $jar" >&2
    if ! log="$(cmake --build "$build" --target vimot_lcmtypes_jar 2>&1)"; then
      printf '%s\n' "$log" | tail -n 20 >&2
      [ -f "$jar" ] || die "building $jar failed (target vimot_lcmtypes_jar; needs javac, jar and liblcm-java, see the CMake warnings)"
      echo "$me: warning: could not rebuild $jar; using the existing one, which may be stale" >&2
    fi
  fi
fi
[ -f "$jar" ] || die "$jar not found. Build it with: cmake --build $build --target vimot_lcmtypes_jar (or set VIMOT_BUILD_DIR)"

# ---- environment for lcm-spy ---------------------------------------------
# jchart2d draws lcm-spy's plots; the installed launcher has it on -cp
# already, launchers that build -cp from CLASSPATH get it from here.
cp="$jar"
if [ -f "$jchart2d" ]; then
  cp="$cp:$jchart2d"
else
  echo "$me: warning: $jchart2d not found (libjchart2d-java); lcm-spy plots will not work" >&2
fi
export CLASSPATH="$cp${CLASSPATH:+:$CLASSPATH}"
export JDK_JAVA_OPTIONS="-XX:+IgnoreUnrecognizedVMOptions${JDK_JAVA_OPTIONS:+ $JDK_JAVA_OPTIONS}"

if [ -z "${DISPLAY:-}" ]; then
  echo "$me: warning: DISPLAY is not set; lcm-spy needs an X display (headless: xvfb-run $me ...)" >&2
fi

if command -v lcm-spy >/dev/null 2>&1; then
  exec lcm-spy "$@"
fi

# No launcher on PATH (e.g. liblcm-bin missing): run lcm-spy's class the way
# the launcher does.
command -v java >/dev/null 2>&1 || die "neither lcm-spy nor java found; install liblcm-bin and a JRE"
lcm_jar="$(pkg-config --variable=classpath lcm-java 2>/dev/null || true)"
[ -n "$lcm_jar" ] || lcm_jar=/usr/share/java/lcm.jar
[ -f "$lcm_jar" ] || die "lcm.jar not found ($lcm_jar); install liblcm-java"
exec java -Djava.net.preferIPv4Stack=true -Xmx128m -ea -cp "$lcm_jar:$jchart2d" lcm.spy.Spy "$@"
