#!/usr/bin/env bash
# The one entry point of the project: installs what is missing, builds, runs scenes, tests,
# validates and benchmarks. `./fsi help` lists the commands.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
BUILD=${FSI_BUILD_DIR:-$ROOT/build}
BIN=$BUILD/bin
DEFAULT_SCENE=$ROOT/runs/default/scene.toml
PACKAGES=(g++ cmake make pkg-config libeigen3-dev libopenmpi-dev openmpi-bin libhdf5-dev
          libfftw3-dev libfftw3-mpi-dev catch2 libfmt-dev libtoml11-dev gmsh libgmsh-dev libspectra-dev
          nlohmann-json3-dev libsuitesparse-dev python3 python3-matplotlib python3-h5py
          python3-numpy python3-mpi4py python3-gmsh)
# What only the tests need: ParaView (the XDMF test) and a virtual display for it to draw on.
TEST_PACKAGES=(python3-paraview xvfb xauth libgl1-mesa-dri libglx-mesa0)

say() { printf '[fsi] %s\n' "$*" >&2; }
die() { printf '[fsi] ERROR: %s\n' "$*" >&2; exit 1; }

usage() {
  cat <<'TXT'
usage: ./fsi COMMAND [ARGS]

  run [SCENE] [--overwrite]   build, then run SCENE (default: runs/default/scene.toml) as one
                              mpirun job of the programs it needs; output in out/<scene name>/
      [--time-limit SECONDS]  checkpoint and stop after this wall time
      [--restart OUTDIR]      resume the run in OUTDIR from its newest complete checkpoint
      [--fluid-ranks P]       the fluid on P ranks (its grid split in row slabs; overrides
                              [fluid] ranks)
  test [CTEST ARGS]           build, then run the whole test suite through CTest
  test --debug [CTEST ARGS]   the same in a Debug build (build-debug/: internal assertions and
                              bounds-checked field access on); unit and integration tests
  test --sanitize [ARGS]      the same in an address + undefined-behaviour sanitizer build
                              (build-sanitize/); unit and integration tests
  validate [CASE...] [-- OPT...]  run the validation cases in runs/ (all when none is named);
                              OPT... go to each case's validate.py (e.g. --short)
  bench [WHAT]                run a benchmark (fluid, solid, fiber, coupler, coupled, protocol,
                              vocal-folds, fluid-ranks);
                              without WHAT, list them
  build                       install missing packages, configure and build (incremental)
  deps                        install missing Debian packages (as root) or list them
  mpirun SCENE                print the mpirun line for SCENE without running it
  movie OUTDIR [--fps N]      an MP4 of a run's output steps, OUTDIR/movie.mp4 (installs ffmpeg)
  report                      speed against error of what validate and bench wrote: out/report/
  help                        this text
TXT
}

# Debian packages: install what is missing when root, otherwise say exactly what to install.
deps() {
  local missing=() wanted=("${PACKAGES[@]}" "$@")
  for p in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ "$(id -u)" -eq 0 ]; then
    say "installing Debian packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >/dev/null
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null \
      || die "apt-get install failed for: ${missing[*]}"
  else
    die "missing Debian packages; install them with: sudo apt-get install ${missing[*]}"
  fi
}

# The kinds of build: release (build/, what runs use), debug and sanitize (checks for tests).
build_flags() {
  case "$1" in
    release) echo "-DCMAKE_BUILD_TYPE=Release" ;;
    debug) echo "-DCMAKE_BUILD_TYPE=Debug" ;;
    sanitize) echo "-DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O1 -DFSI_SANITIZE=ON" ;;
  esac
}

build() {
  local kind=${1:-release}
  shift || true
  deps "$@"
  if [ ! -f "$BUILD/CMakeCache.txt" ]; then
    say "configuring in $BUILD ($kind)"
    cmake -S "$ROOT" -B "$BUILD" $(build_flags "$kind") >/dev/null
  fi
  say "building"
  local log=$BUILD/build.log
  if ! cmake --build "$BUILD" -j "$(nproc)" >"$log" 2>&1; then
    grep -E "error|Error" "$log" | head -40 >&2
    die "build failed; the full log is $log"
  fi
  grep -E "warning" "$log" >&2 || true
}

mpirun_flags() {
  local f=(--oversubscribe)
  [ "$(id -u)" -eq 0 ] && f+=(--allow-run-as-root)
  echo "${f[@]}"
}

# plan SCENE: sets ROLES (roles the scene needs), PROGRAMS (the program playing each, in the same
# order: `[solid] program` may name another than `solid`) and NAME (its output folder name).
plan() {
  local out
  out=$("$BIN/fsi-plan" "$1") || exit 1
  ROLES=$(sed -n 's/^roles: //p' <<<"$out")
  PROGRAMS=$(sed -n 's/^programs: //p' <<<"$out")
  NAME=$(sed -n 's/^name: //p' <<<"$out")
  FLUID_RANKS=${FLUID_RANKS_OPTION:-$(sed -n 's/^fluid_ranks: //p' <<<"$out")}
}

# compose SCENE ARGS...: the mpirun command line, one app context per program the scene needs.
compose() {
  local scene=$1; shift
  plan "$scene"
  CMD=(mpirun $(mpirun_flags))
  local first=1
  for r in $PROGRAMS; do
    [ $first -eq 1 ] || CMD+=(:)
    local n=1
    [ "$r" = fluid ] && n=${FLUID_RANKS:-1}
    CMD+=(-n "$n" "$BIN/$r" "$scene" "$@")
    first=0
  done
}

run() {
  local scene=$DEFAULT_SCENE overwrite=() restart= limit=()
  while [ $# -gt 0 ]; do
    case "$1" in
      --overwrite) overwrite=(--overwrite) ;;
      --restart) [ $# -ge 2 ] || die "--restart needs the output folder of the run to resume"
                 restart=$2; shift ;;
      --time-limit) [ $# -ge 2 ] || die "--time-limit needs a number of seconds"
                    limit=(--time-limit "$2"); shift ;;
      --fluid-ranks) [[ $# -ge 2 && "$2" =~ ^[1-9][0-9]*$ ]] \
                       || die "--fluid-ranks needs a positive whole number of ranks, got '${2:-}'"
                     FLUID_RANKS_OPTION=$2; shift ;;
      -*) die "unknown option '$1' for run (see ./fsi help)" ;;
      *) scene=$1 ;;
    esac
    shift
  done
  [ -f "$scene" ] || die "scene file '$scene' does not exist"
  scene=$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")
  [ -z "$restart" ] || [ ${#overwrite[@]} -eq 0 ] || die "--restart resumes in its folder: no --overwrite"
  build
  plan "$scene"
  # Never overwrite silently: out/NAME, else out/NAME-2, -3, ... Each is taken by one mkdir, so
  # two runs started together get two folders (the programs lock theirs: DIR/.lock).
  # FSI_OUT_ROOT (tests): another folder than out/ to hold the output folders.
  local outs=${FSI_OUT_ROOT:-$ROOT/out}
  local dir=$outs/$NAME n=2
  if [ -n "$restart" ]; then
    # Resume in the run's own folder, from its newest complete checkpoint.
    [ -d "$restart/checkpoint" ] || die "--restart $restart: no checkpoint folder in it"
    dir=$(cd "$restart" && pwd)
    compose "$scene" --restart "$dir" "${limit[@]}"
  else
    mkdir -p "$outs"
    if [ ${#overwrite[@]} -eq 0 ]; then
      until mkdir "$dir" 2>/dev/null; do
        [ -e "$dir" ] || die "cannot create the output folder ${dir#$ROOT/}"
        dir=$outs/$NAME-$n
        n=$((n + 1))
      done
    fi
    compose "$scene" --out-dir "$dir" "${overwrite[@]}" "${limit[@]}"
  fi
  say "running: ${CMD[*]}"
  local rc=0
  launch "${CMD[@]}" || rc=$?
  if [ -n "$(ls -d "$dir"/checkpoint/step_* 2>/dev/null)" ] && { [ $rc -gt 128 ] || grep -q '"stopped_at_step"' "$dir/summary.json" 2>/dev/null; }; then
    say "stopped with a checkpoint; resume with: ./fsi run ${scene#$ROOT/} --restart ${dir#$ROOT/}"
  fi
  [ $rc -eq 0 ] || exit $rc
  [ -d "$dir" ] || die "the output folder ${dir#$ROOT/}/ is gone (deleted during the run?)"
  # Post-processing: the scene's own plot script if its folder has one, else the generic one.
  local plot=$(dirname "$scene")/plot.py
  [ -x "$plot" ] || plot=$ROOT/runs/plot_run.py
  FSI_ROOT=$ROOT FSI_OUT=$dir /usr/bin/python3 "$plot" "$dir" || die "post-processing failed: $plot $dir"
  say "output in ${dir#$ROOT/}/"
  ls "$dir"/*.png >/dev/null 2>&1 && say "picture: $(ls -U "$dir"/picture.png "$dir"/*.png 2>/dev/null | head -1 | sed "s|$ROOT/||")"
  return 0
}

# Open MPI's lines after every MPI_Abort that tell nothing of the cause (its bookkeeping of the
# processes it killed) and mislead: the known ones always, and any ORTE_ERROR_LOG line once a
# program has reported its error; every other line of mpirun's stays visible.
MPI_NOISE='ORTE_ERROR_LOG: (Out of resource|Data unpack (would read past end of buffer|had inadequate space))'

# launch MPIRUN ARGS...: run the job, stderr filtered of MPI_NOISE (the programs' "[role] ERROR:"
# lines kept aside for the summary), and wait for it. SIGTERM, SIGINT or SIGHUP to the launcher
# is passed to mpirun as SIGUSR1, which mpirun forwards to its programs: the run checkpoints the
# step under way and stops (README, "Stopping and resuming"); SIGTERM follows 5 s later and
# SIGKILL 8 s later if it has not ended. The programs watch this process (FSI_LAUNCHER_PID): when it is killed outright (SIGKILL)
# they end themselves within a second. Returns mpirun's exit code, or 128 + the signal's number;
# after a failure it names the program(s) that reported an error.
launch() {
  local tmp errs fifo pid fpid sig= rc kpid=
  tmp=$(mktemp -d)
  errs=$tmp/errors fifo=$tmp/stderr
  : >"$errs"
  mkfifo "$fifo"
  awk -v errs="$errs" -v noise="$MPI_NOISE" '
    $0 ~ noise { next }
    failed && /ORTE_ERROR_LOG: / { next }
    /^\[(fluid|solid|fiber|coupler)\] ERROR: / { failed = 1; print >> errs; fflush(errs) }
    { print; fflush() }' <"$fifo" >&2 &
  fpid=$!
  FSI_LAUNCHER_PID=$$ "$@" 2>"$fifo" &
  pid=$!
  forward() {
    sig=$1
    say "SIG$1: checkpointing and ending the job"
    kill -USR1 "$pid" 2>/dev/null || true
    (sleep 5; kill -TERM "$pid" 2>/dev/null; sleep 3; kill -KILL "$pid" 2>/dev/null) &
    kpid=$!
  }
  trap 'forward TERM' TERM
  trap 'forward INT' INT
  trap 'forward HUP' HUP
  while :; do
    rc=0
    wait "$pid" || rc=$?
    # A trapped signal ends the wait early: wait again while mpirun ends its programs.
    if [ $rc -gt 128 ] && kill -0 "$pid" 2>/dev/null; then continue; fi
    break
  done
  trap - TERM INT HUP
  [ -z "$kpid" ] || kill "$kpid" 2>/dev/null || true
  wait "$fpid" 2>/dev/null || true
  if [ -n "$sig" ]; then
    rm -rf "$tmp"
    say "job ended on SIG$sig"
    return $((128 + $(kill -l "$sig")))
  fi
  if [ $rc -ne 0 ]; then
    local ranks="" k=0 r
    for r in $ROLES; do ranks+="${ranks:+, }$k = $r"; k=$((k + 1)); done
    if [ -s "$errs" ]; then
      local who
      who=$(sed -n 's/^\[\([a-z]*\)\] ERROR: .*/\1/p' "$errs" | awk '!seen[$0]++' | paste -sd, - | sed 's/,/, /g')
      say "job failed (mpirun exit code $rc): the error came from: $who"
      sed -n '1s/^/[fsi]   first error: /p' "$errs" >&2
    else
      say "job failed (mpirun exit code $rc) without a program's ERROR line: a program crashed or was killed (Open MPI's lines above name it by rank; the ranks: $ranks)"
    fi
  fi
  rm -rf "$tmp"
  return $rc
}

test_suite() {
  local kind=release
  case "${1:-}" in
    --debug) kind=debug; shift ;;
    --sanitize) kind=sanitize; shift ;;
  esac
  local select=()
  if [ "$kind" != release ]; then
    BUILD=${FSI_BUILD_DIR:-$ROOT/build-$kind}
    BIN=$BUILD/bin
    # The validation label holds the long runs; in these slower builds the suite checks the code
    # paths (unit and integration tests) unless CTest arguments say otherwise.
    [ $# -eq 0 ] && select=(-L "unit|integration")
  fi
  build "$kind" "${TEST_PACKAGES[@]}"
  cd "$BUILD"
  ctest --output-on-failure -j 2 --timeout 900 "${select[@]}" "$@"
}

validate() {
  build
  # CASE... then, from the first argument that starts with '-' (a lone '--' is dropped), the
  # options every named case's validate.py gets.
  local cases=() opts=()
  while [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; do cases+=("$1"); shift; done
  [ "${1:-}" = "--" ] && shift
  opts=("$@")
  if [ ${#cases[@]} -eq 0 ]; then
    for d in "$ROOT"/runs/*/; do [ -x "$d/validate.py" ] && cases+=("$(basename "$d")"); done
  fi
  [ ${#cases[@]} -gt 0 ] || die "no validation cases in runs/"
  local failed=()
  for c in "${cases[@]}"; do
    local script=$ROOT/runs/$c/validate.py
    [ -x "$script" ] || die "no validation case '$c' (runs/$c/validate.py); cases: $(cd "$ROOT/runs" && ls -d */ | tr -d /)"
    say "validating $c"
    mkdir -p "$ROOT/out/$c"
    if FSI_ROOT=$ROOT FSI_BIN=$BIN FSI_OUT=$ROOT/out/$c "$script" "${opts[@]}"; then
      say "$c: done (out/$c/summary.json)"
    else
      failed+=("$c")
    fi
  done
  [ ${#failed[@]} -eq 0 ] || die "validation failed: ${failed[*]}"
}

bench() {
  build
  local what=${1:-}
  local available=(protocol coupled vocal-folds fluid-ranks)
  for b in "$BIN"/bench_*; do [ -x "$b" ] && available+=("${b##*/bench_}"); done
  if [ -z "$what" ]; then
    say "benchmarks: ${available[*]}"
    return 0
  fi
  mkdir -p "$ROOT/out/bench"
  if [ "$what" = protocol ]; then
    bench_protocol
  elif [ "$what" = coupled ]; then
    bench_coupled
  elif [ "$what" = vocal-folds ]; then
    bench_vocal_folds
  elif [ "$what" = fluid-ranks ]; then
    /usr/bin/python3 "$ROOT/runs/bench-fluid-ranks/bench.py" --bin "$BIN" \
      --out "$ROOT/out/bench/fluid-ranks.json" --work "$ROOT/out/bench/fluid-ranks"
  elif [ -x "$BIN/bench_$what" ]; then
    "$BIN/bench_$what" --out "$ROOT/out/bench/$what.json"
  else
    die "no benchmark '$what'; available: ${available[*]}"
  fi
}

# The cost of one empty protocol step: four programs, no bodies, many steps.
bench_protocol() {
  local scene=$ROOT/runs/bench-protocol/scene.toml dir=$ROOT/out/bench/protocol
  local f=$(mpirun_flags)
  local a=("$scene" --out-dir "$dir" --overwrite)
  mpirun $f -n 1 "$BIN/null_solver" fluid "${a[@]}" : -n 1 "$BIN/null_solver" solid "${a[@]}" \
    : -n 1 "$BIN/null_solver" fiber "${a[@]}" : -n 1 "$BIN/coupler" "${a[@]}"
  /usr/bin/python3 - "$dir/summary.json" "$ROOT/out/bench/protocol.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
r = {"steps": s["steps"], "us_per_step": s["coupler"]["us_per_step"],
     "note": "four programs (null solvers), no bodies: the whole per-step message sequence"}
json.dump(r, open(sys.argv[2], "w"), indent=2)
print(f"empty protocol step: {r['us_per_step']:.1f} us over {r['steps']} steps")
print("notes: change | predicted | measured")
print("  polite wait (yield, then sleep 5..200 us) instead of Open MPI's busy poll | programs that wait leave the cores | not measured then")
print("  timer slack 1 us instead of Linux's 50 us | shorter wake-ups | 388 -> 174 us per empty step (one pair of runs)")
print("  sleep cap 50 us instead of 200 us | faster hand-over | empty step 270-440 -> 133-218 us, but the default")
print("      coupled scene 0.9-1.1 -> 1.6-1.7 s: the waiting programs steal the cores; kept at 200 us")
print("  yields only, no sleeps (the sleeps and the timer slack removed) | no late wake-ups | empty step 41-90 ->")
print("      37-47 us; default scene 57.6-58.5 -> 52.7-53.5 s, fibers-on-block 5.1 -> 3.3-3.5 s, ctest -j2 152 -> 141 s")
print("      (interleaved runs); Open MPI's busy poll, which yields when oversubscribed: 50.9-53.6 s, 2.9-3.1 s")
PY
}

# A coupled step at the paper's Turek-Hron FSI2 resolution: the coupler's work and the message
# traffic against the fluid step, the whole step against the solvers' own work (negative when
# their work ahead of the input hides the coupling) and against the sum of the coupler's phases.
bench_coupled() {
  local scene=$ROOT/runs/bench-coupled/scene.toml dir=$ROOT/out/bench/coupled
  compose "$scene" --out-dir "$dir" --overwrite
  "${CMD[@]}"
  /usr/bin/python3 - "$dir/summary.json" "$ROOT/out/bench/coupled.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
n = s["steps"]
c = {k: v["seconds_per_call"] * 1e3 for k, v in s["coupler"]["phases"].items()}
fluid = sum(s["fluid"]["phases"].values()) / n * 1e3
# Each solver's driver times its step from input received to answer sent (port_seconds) and the
# work it does ahead of its input (ahead_seconds: the fluid's next explicit terms and predictor,
# while the coupler runs the solid and the footprint). The coupler's phase for a solver beyond
# that solver's port time is the messages'.
port = s["fluid"]["port_seconds"] / n * 1e3
ahead = s["fluid"].get("ahead_seconds", 0) / n * 1e3
fluid_step = port + ahead
traffic = c["fluid"] - port
solid_port = s["solid"]["port_seconds"] / n * 1e3
solid_ahead = s["solid"].get("ahead_seconds", 0) / n * 1e3
work = c.get("footprint", 0) + c.get("reaction", 0) + c.get("fibers", 0)
step = s["coupler"]["us_per_step"] / 1e3
parts = c["fluid"] + c.get("solid", 0) + c.get("fiber", 0) + work
r = {"steps": n, "grid": s["fluid"].get("grid"), "ms_per_step": {
        "whole step": step, "fluid step (all its work)": fluid_step,
        "  of which ahead of its input": ahead, "  solver phases": fluid,
        "messages to and from the fluid": traffic, "footprint": c.get("footprint", 0),
        "reaction": c.get("reaction", 0), "solid round trip": c.get("solid", 0),
        "solid step (all its work)": solid_port + solid_ahead,
        "  of which ahead of its forces": solid_ahead},
     "coupler_work_and_traffic_to_fluid_step": (work + traffic) / fluid_step,
     # What the coupling adds to the clock over the two solvers' own work done one after the
     # other (negative when the work done ahead hides more than the coupling costs).
     "step_minus_fluid_and_solid_steps_ms": step - fluid_step - solid_port - solid_ahead,
     "step_to_sum_of_parts": step / parts}
json.dump(r, open(sys.argv[2], "w"), indent=2)
for k, v in r["ms_per_step"].items():
    print(f"  {k:30s} {v:8.3f} ms")
print(f"  coupler work + traffic / fluid step: {r['coupler_work_and_traffic_to_fluid_step']:.2f}"
      " (target 0.10)")
print(f"  whole step - fluid step - solid step: {r['step_minus_fluid_and_solid_steps_ms']:.3f} ms")
print(f"  whole step / sum of the coupler's phases: {r['step_to_sum_of_parts']:.3f} (1: the coupler's"
      " clock accounts for the step; the solvers' work ahead runs inside its phases)")
print("notes: change | predicted | measured (whole step, interleaved runs against the code before)")
print("  footprint: one record per piece, barycentric map per triangle, helpers inlined | -20 % footprint"
      " | bench_coupler one thread 3.0-3.1 -> 2.4-2.6 ms")
print("  fluid keeps its predictor fields only when a step may be repeated (protocol v4) | -0.7 ms"
      " | fluid phases 15.5-15.9 -> 13.1-13.9 ms")
print("  fluid's next explicit terms after answering, its predictor on step_begin | -5 ms"
      " | with the two above: 26.2-28.3 -> 21.0-23.5 ms")
print("  solid factorises its first Newton matrix while the fluid steps; factor reused when the matrix"
      " is unchanged | -3 ms | solid round trip 8.5 -> 4.2 ms, whole step 19-22 ms")
print("  solid's step_begin after the footprint (its factorisation no longer beside the clipping) |"
      " -1 ms | 17.2-18.4 ms; all together 24.7-27.4 -> 17.3-18.8 ms (x 0.69)")
print("  a step that cannot be repeated is committed once answered; the fluid begins the next one"
      " (explicit terms and predictor) at once, beside the solid's step | -1 ms | 15.1-17.0 ms,"
      " messages 1.3-1.6 -> 0.6-1.0 ms, footprint 2.0-3.1 -> 1.6-2.5 ms; all together 26.0-29.4"
      " -> 14.4-17.8 ms (x 0.56-0.61)")
print("  waiting paced by the expected arrival instead of a fixed 200 us cap | faster pick-up |"
      " none measurable (messages 1.0-1.4 fixed, 1.4-1.6 ms paced): not kept")
print("  the coupler alone with a 50 us sleep cap (the hub picks its answers up sooner) | -0.3 ms |"
      " messages 1.1 -> 0.8 ms but the whole step no shorter (15.6-16.0 against 14.5-16.4 ms) and the"
      " default scene slower (3.9-5.7 against 3.4-4.2 ms): not kept")
print("  fixed bodies (the cylinder) handled per face, not per piece, after their one clipping | -0.3 ms"
      " footprint | footprint 1.40-2.41 -> 1.13-1.68 ms, coupler work + traffic / fluid step 0.22-0.33"
      " -> 0.19-0.26 (nine interleaved pairs); whole step within noise (12.1-15.8 against 12.1-15.1 ms)")
print("  waiting by yields only, no sleeps (common/runtime.cpp) | -0.3 ms messages | within noise at this grid:"
      " whole step 12.1-13.4 -> 11.3-12.9 ms, messages 0.59-0.92 -> 0.46-0.82 ms, ratio 0.19-0.26 -> 0.20-0.22"
      " (three interleaved pairs): the messages here are not the sleeps' late wake-ups")
print("  solid keeps the last step's factor while its first solve contracts 1000x (solid/newton.cpp,"
      " kKeepRatio) | -1.5 ms of solid CPU beside the fluid | here 1 factorisation in 200 steps, solid"
      " round trip 2.6-3.9 -> 1.9 ms, whole step 10.9 ms (one run, not interleaved); glycocalyx elastic"
      " wall with fibers 196 -> 289 steps/s (old and new one after another)")
print("  work ahead on a thread of its own at nice 19 (so a waking coupler gets a core at once) |"
      " -1 ms messages | worse: 18.2-22.7 ms (messages 2.1-3.3: the fluid's predictor starved beside"
      " the clipping, with one footprint thread too): not kept")
PY
}

# A coupled step of the vocal folds on the paper's grid (runs/bench-vocal-folds): where it goes.
bench_vocal_folds() {
  local scene=$ROOT/runs/bench-vocal-folds/scene.toml dir=$ROOT/out/bench/vocal-folds
  compose "$scene" --out-dir "$dir" --overwrite
  "${CMD[@]}"
  /usr/bin/python3 "$ROOT/runs/bench-vocal-folds/report.py" "$dir/summary.json" \
    "$ROOT/out/bench/vocal-folds.json"
  # The closing glottis: h = 0 from rest (the folds in contact from the first step, each fold's
  # self-contact, a contact plane at each wall), neo-Hookean folds, the fluid sub-cycled, 5000
  # steps (runs/vocal-folds/README.md).
  say "vocal folds at h = 0: contact, wall planes, substeps"
  FSI_OUT="$ROOT/out/bench/vocal-folds-contact" FSI_BIN="$BIN" /usr/bin/python3 \
    "$ROOT/runs/vocal-folds/validate.py" --run 0 --grid paper --t-end 0.25 --upwind 0.2 --convection central \
    --material neo-hookean --wall-planes --substeps 4 > /dev/null ||
    die "the vocal folds' contact bench failed (out/bench/vocal-folds-contact)"
  /usr/bin/python3 "$ROOT/runs/bench-vocal-folds/report.py" \
    "$ROOT/out/bench/vocal-folds-contact/neo-hookean/planes/substeps-4/run_h0_paper_b0.2/summary.json" \
    "$ROOT/out/bench/vocal-folds-contact.json"
  /usr/bin/python3 - <<'PY'
print("notes: change | predicted | measured")
print("  none yet for speed; first measurement on an idle 2-core machine: 5.08 ms per step (197")
print("      steps/s), 20.3 min for t = 12; footprint 1.39, fluid round trip 2.04 (its work 1.69),")
print("      solid round trip 1.42 (assembly 0.70 in two Newton iterations), messages 0.35 + 0.54 ms")
print("  each link packs and receives into kept buffers (was: a fresh vector per message, its")
print("      pages faulted in); the footprint's faces read off their marks (was: sorted) | messages")
print("      and footprint down | old and new code alternately, two pairs: 5.46, 4.55 -> 4.82, 3.65")
print("      ms per step (21.9, 18.2 -> 19.3, 14.6 min for t = 12); messages 0.35 + 0.54 -> 0.14-0.26")
print("      + 0.14-0.24 ms")
print("  tried and not kept: the last Newton iteration's residual without its matrix (-0.2 ms")
print("      predicted): the residual's round-off floor and a pending prescribed increment take the")
print("      element matrices, so the step would not stay bit for bit")
print("  each fold's self-contact (the scene's two self pairs) | the solid's detection, a few")
print("      0.1 ms | without and with, one run each: 4.13 -> 4.21 ms per step, solid round trip")
print("      1.03 -> 1.28 ms (16.5 -> 16.8 min for t = 12)")
print("  contact bench (h = 0, planes, substeps): the contact complement over a working set (the")
print("      active slots and those the free step takes through; was: every candidate within")
print("      reach, a solve with the factor each) | the solid's solve down | old and new code, one")
print("      run each: 21.7 -> 5.4 ms per step, solid solve 15.9 -> 0.21 ms")
print("  open contact candidates keep the look-ahead's factor (was: any contact slot made every")
print("      Newton iteration after the first factorise) | one factorisation per step less | h = 0.01")
print("      from its checkpoint at t = 11.5, 10 000 steps, old and new code one after the other:")
print("      solid round trip 2.31 -> 1.13 ms, 6.39 -> 4.99 ms per step")
print("  the fluid's transforms along y as a vectorised matrix product where FFTW has only its")
print("      generic O(n^2) code (101 rows at h = 0.01) | Poisson 1.4 -> 0.5 ms | the same segment:")
print("      Poisson 1.42 -> 0.46 ms, 4.99 -> 3.87 ms per step (15.5 min for t = 12)")
print("  tried, kept opt-in (solid.predictor = \"acceleration\"): Newton starts at the trapezoidal")
print("      step with the start's forces, not at x^n | one iteration of two | h = 0, upwind3, 5000")
print("      steps from rest, one run each: 1.98 -> 1.00 iterations, 4.36 -> 3.64 ms per step; to")
print("      t = 12 the run stopped at t = 7.14 in contact (runs/vocal-folds/README.md), so off")
print("  the look-ahead in lasting contact: the last step's active slots' curvature added, the sum")
print("      factorised while the fluid steps; iteration 0 finds it when the values agree bit for")
print("      bit | one factorisation per contact step off the critical path | h = 0, upwind3,")
print("      predictor, 2000 steps from t = 7, two pairs alternately: solid round trip 3.17, 3.43")
print("      -> 2.73, 2.77 ms; 7.49, 7.72 -> 7.07, 7.22 ms per step; the same bits")
print("  -march=native (FSI_NATIVE) | the stencil loops vectorised with AVX2 | the same")
print("      segment, portable and native alternately: the fluid's predictor phase 4.90, 4.79 ->")
print("      3.94, 4.28 s; the whole step 8.42, 7.88 -> 8.15, 8.54 ms (within the machine's noise)")
print("  modified Newton in contact steps (the factor kept while the residual falls 100x per")
print("      iteration; was: every iteration in contact factorised) | two factorisations of three")
print("      per contact step | h = 0, upwind3, 2000 steps from t = 11, two pairs alternately:")
print("      factorisations 4117 -> 2309; 7.13, 9.25 -> 6.24, 7.10 ms per step")
print("  the assembly without the neo-Hookean energy (log1p, expm1 and pow per element) | -20 %")
print("      of the assembly | the same segment, two pairs: assembly 2.26, 2.57 -> 1.96, 1.96 s;")
print("      6.24, 7.10 -> 5.60, 5.83 ms per step")
print("  self-contact detection through bins of the surface edges; the footprint's faces")
print("      radix-sorted (the folds on the two walls span the grid) | -0.2 ms each (perf: 5 % of")
print("      the solid, 9 % of the coupler) | the same segment, one run: the same bits; 5.60, 5.83")
print("      -> 6.02 ms per step, footprint 1.50, 1.77 -> 1.39 ms (within the machine's noise)")
print("  to t = 12 with all of these and two robustness rules (runs/vocal-folds/README.md): 1 477")
print("      -> 1 363 s (6.16 -> 5.68 ms per step; solid 2.85 -> 1.97, footprint 1.44 -> 1.81,")
print("      fluid 1.67 -> 1.70 ms)")
print("  the convection-diffusion kernel's loops vectorised (GCC wanted more run-time alias checks")
print("      than it makes; the outputs are other fields, said with #pragma GCC ivdep) | the fluid's")
print("      predictor down | the same segment (51 % of the steps sub-cycled), alternately: predictor")
print("      phase 3.44, 3.50 -> 2.20, 2.07 s; the same bits")
print("  each footprint thread's lists on cache lines of their own (the u- and v-families' piece")
print("      lists were neighbours: each append invalidated the other thread's line; perf: 58 % of")
print("      the piece emitter on the list's end) | footprint down | the same segment, three pairs on")
print("      a loaded machine: footprint 2.22, 2.05, 2.07 -> 1.67, 1.51, 1.67 ms; the same bits")
print("  to t = 12 with both, alone: 1 363 -> 1 218 s (5.68 -> 5.07 ms per step; solid 1.97 -> 1.89,")
print("      footprint 1.81 -> 1.35, fluid 1.70 -> 1.65 ms; CPU 2 694 -> 2 404 s); the same")
print("      trajectory (67 closures, impulse ratio 0.0600)")
print("  tried, not kept: the footprint's second thread kept from step to step (a futex wait between")
print("      steps; was: a thread started and joined per step) | -0.1 ms | the same segment, three")
print("      pairs: footprint 1.38, 1.34, 1.23 against 1.77, 1.27, 1.20 ms, within the noise; one")
print("      thread instead of two: 1.68, 1.55, 1.48 against 1.22, 1.23, 1.21 ms (two stay)")
print("  Newmark gamma = 0.55 in the scene (damps the cover's element-scale vibration, which the")
print("      trapezoidal rule kept) | fewer Newton iterations and cut steps | to t = 12 alone: 1 218")
print("      -> 1 091 s (5.07 -> 4.55 ms per step; solid 1.89 -> 1.56, footprint 1.35 -> 1.24, fluid")
print("      1.65 -> 1.59 ms; Newton 3.46 -> 3.11 per step, 4 -> 1 steps cut; CPU 2 404 -> 2 091 s);")
print("      a new trajectory (67 closures, 5.74)")
print("  body_viscosity = \"none\" (the default since): its correction with each flux once on the")
print("      footprint's boxes, each alpha read once (was: per face, its fluxes and the alpha they read")
print("      again, 11 to 13 reads a face) | most of the correction's 0.5 ms per step | h = 0,")
print("      upwind3, 5000 steps from rest, one run before, two after: the fluid's predictor phase")
print("      1.29 -> 1.02, 1.06 ms per step (Kelvin-Voigt folds 0.78); the same bits")
print("  tried, not kept: the solid's factor kept across steps with open contact candidates (the")
print("      wall planes, the self-contact; was: any slot made every step factorise ahead) | the")
print("      look-ahead's 1.5 ms of CPU per step | h = 0 from its checkpoint at t = 0.5, 10 000")
print("      steps, one run each: factorisations 10 012 -> 300, but Newton 2.17 -> 3.76 iterations")
print("      per step (the held factor converges linearly, the look-ahead's exact one")
print("      quadratically), solid round trip 1.28 -> 1.81 ms, 4.83 -> 5.21 ms per step: the")
print("      look-ahead runs beside the fluid, off the critical path, so removing it gains nothing")
print("      (measured again from t = 11, 5 000 steps: factorisations 5 000 -> 8, solves per step 3.0")
print("      -> 4.4, 5.49 -> 5.60 ms per step)")
print("  tried, not kept: the two folds' elements assembled side by side on two threads, one per")
print("      body (the same bits) | -0.1 ms per Newton iteration | h = 0 from its checkpoint at")
print("      t = 11, 5 000 steps, alternately: every assembly threaded 6.09, 6.10 against 5.49 ms per")
print("      step (the look-ahead's second thread took the fluid's core: its round trip 1.90 ->")
print("      2.44 ms); Newton's assemblies only 5.67, 5.77, 6.29 against 6.03, 5.44, 5.96 ms: no")
print("      core is idle while the solid works (the fluid's work ahead, the waiting programs)")
print("  a step's first residual from the look-ahead's (the coupling force added last; the same bits")
print("      as assembling it) | one of 4 element passes per step off the solid's critical path,")
print("      -0.2 ms | h = 0 from t = 11, 2 000 steps, one run each beside another job: solid work on")
print("      its input 1.87 -> 1.40 ms, assembly 1.06 -> 0.70 ms per step; to t = 12 alone (with the")
print("      vertex zone's new gap, another trajectory): solid work on its input 1.76 -> 1.60 ms,")
print("      assembly 0.94 -> 0.78 ms per step, but 1 321 -> 1 358 s (5.50 -> 5.66 ms per step: the")
print("      messages 0.58 -> 0.86 ms and the footprint 1.48 -> 1.61 ms on that day)")
PY
}

# movie OUTDIR [ARGS]: an MP4 of a run folder (runs/movie.py); ffmpeg is installed only for this,
# so that a newcomer's `./fsi run` stays light.
movie() {
  local dir=${1:-}
  [ -n "$dir" ] || die "usage: ./fsi movie OUTDIR [--fps N] (a run's output folder, e.g. out/default)"
  [ -d "$dir" ] || die "no output folder '$dir'"
  shift
  deps ffmpeg
  /usr/bin/python3 "$ROOT/runs/movie.py" "$dir" "$@"
}

# report [ARGS]: speed against error of the validated cases and the benchmarks (runs/report.py),
# from out/<case>/summary.json and out/bench/*.json into out/report/index.html.
report() {
  deps
  /usr/bin/python3 "$ROOT/runs/report.py" --out "$ROOT/out" "$@"
}

cmd=${1:-help}
[ $# -gt 0 ] && shift
# `exit` on the esac's line: bash has read everything it will run before it starts the command,
# so a checkout or an edit of this file while a long command runs cannot garble its end.
case "$cmd" in
  run) run "$@" ;;
  test) test_suite "$@" ;;
  validate) validate "$@" ;;
  bench) bench "$@" ;;
  build) build ;;
  deps) deps ;;
  movie) movie "$@" ;;
  report) report "$@" ;;
  mpirun) build >/dev/null; compose "$(realpath "${1:?scene}")"; echo "${CMD[*]}" ;;
  help | -h | --help) usage ;;
  *) usage; die "unknown command '$cmd'" ;;
esac; exit $?
