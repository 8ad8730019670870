#!/usr/bin/env bash
# End-to-end benchmark of the g2s command line: meshes each cloud N times on one thread, measures
# the meshes, prints a Markdown table and writes bench/results/<UTC date>-<commit>.json.
#
#   bench/run.sh [--build DIR] [--runs N] [--out DIR] [--timeout SECONDS] [CLOUD...]
#
# Needs only bash (4+), coreutils, the built `g2s` and GNU time (/usr/bin/time -v, Debian package
# `time`); no python. See bench/README.md.
set -uo pipefail

usage() {
  cat <<'EOF'
Usage: bench/run.sh [--build DIR] [--runs N] [--out DIR] [--timeout SECONDS] [CLOUD...]

  --build DIR   build folder holding the g2s binary (default: build, relative to the repository)
  --runs N      times each cloud is meshed (default 3); the table shows the median [min-max]
  --out DIR     folder for the JSON results (default: bench/results in the repository)
  --timeout S   stop a `g2s mesh` run after S seconds and record it as failed (exit 124);
                default: no limit
  CLOUD...      point clouds to mesh (PLY, XYZ). Default: every *.ply in
                ${G2S_DATA_DIR:-../shared/data} (relative to the repository) plus a 2M-point
                synthetic torus made with `g2s synth torus --points 2M`.

Each run is `g2s mesh CLOUD -o TMP.stl --json --threads 1` under `/usr/bin/time -v`: points,
triangles and seconds come from its JSON, the peak RSS from GNU time. The last mesh is then
measured once with `g2s stats TMP.stl --points CLOUD --json`. A failing `g2s mesh` is recorded
(its exit code) and the run goes on. Temporary files go to ${TMPDIR:-/tmp} and are removed.
EOF
}

die() {
  printf 'bench/run.sh: %s\n' "$*" >&2
  exit 2
}

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd) || die "cannot find the repository"
build=build
runs=3
out=bench/results
timeout=
clouds=()
while (($#)); do
  case $1 in
    --build) (($# >= 2)) || die "--build needs a folder"; build=$2; shift 2 ;;
    --build=*) build=${1#*=}; shift ;;
    --runs) (($# >= 2)) || die "--runs needs a number"; runs=$2; shift 2 ;;
    --runs=*) runs=${1#*=}; shift ;;
    --out) (($# >= 2)) || die "--out needs a folder"; out=$2; shift 2 ;;
    --out=*) out=${1#*=}; shift ;;
    --timeout) (($# >= 2)) || die "--timeout needs a number of seconds"; timeout=$2; shift 2 ;;
    --timeout=*) timeout=${1#*=}; shift ;;
    -h | --help) usage; exit 0 ;;
    --) shift; clouds+=("$@"); break ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *) clouds+=("$1"); shift ;;
  esac
done
[[ $runs =~ ^[1-9][0-9]*$ ]] || die "--runs must be a positive whole number, not '$runs'"
[[ -z $timeout || $timeout =~ ^[0-9]+(\.[0-9]+)?$ ]] || die "--timeout must be a number of seconds, not '$timeout'"
limit=()
[[ -n $timeout ]] && limit=(timeout "$timeout")
[[ $build == /* ]] || build=$repo/$build
[[ $out == /* ]] || out=$repo/$out
g2s=$build/g2s
[[ -x $g2s ]] || die "no g2s binary at $g2s: build first (cmake -S . -B build -G Ninja && cmake --build build) or pass --build DIR"
[[ -x /usr/bin/time ]] || die "GNU time is needed at /usr/bin/time (apt-get install time)"
/usr/bin/time -v -o /dev/null true 2>/dev/null || die "/usr/bin/time does not take -v: GNU time is needed (apt-get install time)"
mkdir -p "$out" || die "cannot create $out"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/g2s-bench.XXXXXX") || die "cannot create a temporary folder"
trap 'rm -rf "$tmp"' EXIT
trap 'printf "\nbench/run.sh: interrupted\n" >&2; exit 130' INT TERM

log() { printf '%s\n' "$*" >&2; }

# ---- small pure-bash helpers ------------------------------------------------------------------

# json_number KEY FILE: the first number stored under "KEY" in FILE (empty if none). The first
# match is the top-level one in `g2s mesh --json`, whose nested "stats" object comes last.
json_number() {
  local text
  text=$(<"$2") || return 0
  text=${text//$'\n'/ }
  local re="\"$1\"[[:space:]]*:[[:space:]]*(-?[0-9][0-9.eE+-]*)"
  [[ $text =~ $re ]] && printf '%s' "${BASH_REMATCH[1]}"
}

# json_string TEXT: TEXT as a JSON string literal (control characters dropped).
json_string() {
  local s=$1
  s=${s//\\/\\\\}
  s=${s//\"/\\\"}
  s=${s//[$'\001'-$'\037']/}
  printf '"%s"' "$s"
}

# to_ms SECONDS: "12.345" -> 12345 (the mesh JSON prints seconds with 3 decimals).
to_ms() {
  local s=$1 whole frac
  whole=${s%%.*}
  [[ $s == *.* ]] && frac=${s#*.} || frac=
  frac=${frac}000
  frac=${frac:0:3}
  printf '%d' $((10#${whole:-0} * 1000 + 10#$frac))
}

# fixed VALUE SCALE DECIMALS: integer VALUE/SCALE printed with DECIMALS places (10^DECIMALS =
# SCALE), e.g. fixed 12345 1000 3 -> 12.345.
fixed() {
  local v=$1 scale=$2 d=$3
  if ((d == 0)); then printf '%d' "$v"; else printf '%d.%0*d' $((v / scale)) "$d" $((v % scale)); fi
}

# secs MS REFERENCE_MS: MS milliseconds as seconds, 3 decimals when the reference is under 10 s,
# else 2 (rounded).
secs() {
  if (($2 < 10000)); then fixed "$1" 1000 3; else fixed $((($1 + 5) / 10)) 100 2; fi
}

# group N: 1234567 -> 1,234,567 (anything but digits is printed as it is)
group() {
  local n=$1 outp=
  [[ $n =~ ^[0-9]+$ ]] || { printf '%s' "$n"; return; }
  while ((${#n} > 3)); do
    outp=,${n: -3}$outp
    n=${n:0:${#n}-3}
  done
  printf '%s%s' "$n" "$outp"
}

# ---- the machine and the code -----------------------------------------------------------------

arch=$(uname -m)
cpu=unknown
while IFS= read -r line; do
  if [[ $line == "model name"* ]]; then cpu=${line#*: }; break; fi
done </proc/cpuinfo
cores=$(nproc)
ram_kb=0
while read -r key value _; do
  if [[ $key == MemTotal: ]]; then ram_kb=$value; break; fi
done </proc/meminfo
ram_mb=$(((ram_kb + 512) / 1024))
commit=unknown
changes=()
if command -v git >/dev/null && git -C "$repo" rev-parse --git-dir >/dev/null 2>&1; then
  commit=$(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)
  while IFS= read -r line; do
    [[ -n $line ]] && changes+=("${line:3}")
  done < <(git -C "$repo" status --porcelain -- src include tools CMakeLists.txt 2>/dev/null)
fi
now=$(date -u +%Y-%m-%dT%H:%M:%SZ)
day=${now%%T*}
version=$("$g2s" --version 2>/dev/null)
built=$(date -u -r "$g2s" +%Y-%m-%dT%H:%M:%SZ)
dirty_note=
((${#changes[@]})) && dirty_note=" plus uncommitted changes (${changes[*]})"

# ---- the clouds -------------------------------------------------------------------------------

if ((${#clouds[@]} == 0)); then
  data=${G2S_DATA_DIR:-../shared/data}
  [[ $data == /* ]] || data=$repo/$data
  shopt -s nullglob
  clouds=("$data"/*.ply)
  shopt -u nullglob
  ((${#clouds[@]})) || log "no *.ply in $data (set G2S_DATA_DIR); going on with the synthetic torus only"
  torus=$tmp/synthetic-torus-2M.ply
  log "making the 2M-point synthetic torus: g2s synth torus --points 2M"
  if "$g2s" synth torus --points 2M -o "$torus" 2>"$tmp/synth.err"; then
    clouds+=("$torus")
  else
    log "g2s synth failed (exit $?): $(<"$tmp/synth.err"); the torus is left out"
  fi
fi

log "g2s: $g2s ($version, built $built), commit $commit$dirty_note"
log "machine: $arch, $cpu, $cores cores, $ram_mb MB RAM; $runs run(s) per cloud, --threads 1"

# ---- the runs ---------------------------------------------------------------------------------

table=()  # Markdown rows
rows=()   # JSON objects
stl=$tmp/mesh.stl
index=0
for cloud in "${clouds[@]}"; do
  index=$((index + 1))
  name=${cloud##*/}
  name=${name%.*}
  points='' triangles='' exit_code=0 error=''
  times_ms=() seconds_json=() rss_kb=()
  for ((r = 1; r <= runs; r++)); do
    rm -f "$stl"
    /usr/bin/time -v -o "$tmp/time.txt" "${limit[@]}" \
      "$g2s" mesh "$cloud" -o "$stl" --json --threads 1 >"$tmp/mesh.json" 2>"$tmp/mesh.err"
    rc=$?
    rss=
    while IFS= read -r line; do
      [[ $line == *"Maximum resident set size (kbytes):"* ]] && rss=${line##*: }
    done <"$tmp/time.txt"
    seconds=$(json_number seconds "$tmp/mesh.json")
    if ((rc != 0)) || [[ -z $seconds ]]; then
      ((rc != 0)) || rc=1
      exit_code=$rc
      error=$(head -c 400 "$tmp/mesh.err")
      ((rc == 124)) && [[ -n $timeout ]] && error="timed out after $timeout s${error:+; }$error"
      log "[$index/${#clouds[@]}] $name: run $r/$runs FAILED (exit $rc): $error"
      break
    fi
    points=$(json_number points "$tmp/mesh.json")
    triangles=$(json_number triangles "$tmp/mesh.json")
    times_ms+=("$(to_ms "$seconds")")
    seconds_json+=("$seconds")
    rss_kb+=("${rss:-0}")
    log "[$index/${#clouds[@]}] $name: run $r/$runs: $points points -> $triangles triangles in $seconds s, peak RSS ${rss:-?} kB"
  done

  if ((exit_code != 0)); then
    table+=("| $name | — | — | failed (exit $exit_code) | — | — | — | — | — | — | — | — |")
    rows+=("{\"cloud\":$(json_string "$name"),\"path\":$(json_string "$cloud"),\"exit_code\":$exit_code,\"error\":$(json_string "$error"),\"seconds\":[$(IFS=,; echo "${seconds_json[*]}")]}")
    continue
  fi

  # Median, min and max of the run times, in ms.
  mapfile -t sorted < <(printf '%s\n' "${times_ms[@]}" | sort -n)
  n=${#sorted[@]}
  if ((n % 2)); then
    median=${sorted[n / 2]}
  else
    median=$(((sorted[n / 2 - 1] + sorted[n / 2] + 1) / 2))
  fi
  min=${sorted[0]} max=${sorted[n - 1]}
  peak_kb=0
  for k in "${rss_kb[@]}"; do ((k > peak_kb)) && peak_kb=$k; done
  peak_mb=$(((peak_kb + 512) / 1024))
  if ((median > 0)); then
    ktps10=$(((triangles * 10 * 1000 / median + 500) / 1000))  # k-triangles/s x10
    ktps=$(fixed "$ktps10" 10 1)
  else
    ktps=
  fi

  # Defects of the last mesh, with the cloud's coverage.
  "$g2s" stats "$stl" --points "$cloud" --json >"$tmp/stats.json" 2>"$tmp/stats.err"
  stats_rc=$?
  rm -f "$stl"
  declare -A s=()
  for key in non_manifold_edges non_manifold_vertices orientation_conflicts boundary_edges holes \
    input_points covered_points; do
    s[$key]=$(json_number "$key" "$tmp/stats.json")
  done
  stats_json=null
  coverage=—
  if ((stats_rc == 0)); then
    stats_json=$(<"$tmp/stats.json")
    stats_json=${stats_json//$'\n'/}
    stats_json=${stats_json//  \"/\"}
    if [[ -n ${s[input_points]} && ${s[input_points]} -gt 0 ]]; then
      cov100=$(((s[covered_points] * 100000 / s[input_points] + 5) / 10))  # percent x100
      coverage=$(fixed "$cov100" 100 2)
    fi
  else
    log "[$index/${#clouds[@]}] $name: g2s stats FAILED (exit $stats_rc): $(head -c 400 "$tmp/stats.err")"
    for key in "${!s[@]}"; do s[$key]=—; done
  fi

  seconds_cell="$(secs "$median" "$median") [$(secs "$min" "$median")–$(secs "$max" "$median")]"
  table+=("| $name | $(group "$points") | $(group "$triangles") | $seconds_cell | ${ktps:-—} | $peak_mb | $(group "${s[non_manifold_edges]}") | $(group "${s[non_manifold_vertices]}") | $(group "${s[orientation_conflicts]}") | $(group "${s[boundary_edges]}") | $(group "${s[holes]}") | $coverage |")
  rows+=("{\"cloud\":$(json_string "$name"),\"path\":$(json_string "$cloud"),\"exit_code\":0,\"points\":$points,\"triangles\":$triangles,\"seconds\":[$(IFS=,; echo "${seconds_json[*]}")],\"seconds_median\":$(fixed "$median" 1000 3),\"seconds_min\":$(fixed "$min" 1000 3),\"seconds_max\":$(fixed "$max" 1000 3),\"ktriangles_per_second\":${ktps:-null},\"peak_rss_kb\":[$(IFS=,; echo "${rss_kb[*]}")],\"peak_rss_mb\":$peak_mb,\"stats_exit_code\":$stats_rc,\"stats\":$stats_json}")
  unset s
done

# ---- the report -------------------------------------------------------------------------------

echo
echo "g2s $commit$dirty_note, $now; $arch, $cpu, $cores cores, $ram_mb MB RAM; \`g2s mesh --threads 1\`, $runs run(s) per cloud"
echo
echo "| cloud | points | triangles | seconds, median [min–max] | k-triangles/s | peak RSS MB | non-manifold edges | non-manifold vertices | orientation conflicts | boundary edges | holes | coverage % |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
printf '%s\n' "${table[@]}"

result=$out/$day-$commit.json
k=2
while [[ -e $result ]]; do
  result=$out/$day-$commit-$k.json
  k=$((k + 1))
done
changes_json=
for c in "${changes[@]}"; do changes_json+=${changes_json:+,}$(json_string "$c"); done
{
  printf '{\n'
  printf '  "date": "%s",\n' "$now"
  printf '  "commit": %s,\n' "$(json_string "$commit")"
  printf '  "uncommitted_changes": [%s],\n' "$changes_json"
  printf '  "g2s": %s,\n' "$(json_string "$version")"
  printf '  "g2s_built": "%s",\n' "$built"
  printf '  "machine": {"arch": %s, "cpu": %s, "cores": %d, "ram_mb": %d},\n' \
    "$(json_string "$arch")" "$(json_string "$cpu")" "$cores" "$ram_mb"
  printf '  "command": "g2s mesh CLOUD -o OUT.stl --json --threads 1; g2s stats OUT.stl --points CLOUD --json",\n'
  printf '  "runs": %d,\n' "$runs"
  printf '  "timeout_seconds": %s,\n' "${timeout:-null}"
  printf '  "rows": [\n'
  for ((i = 0; i < ${#rows[@]}; i++)); do
    printf '    %s%s\n' "${rows[i]}" "$( ((i + 1 < ${#rows[@]})) && echo ,)"
  done
  printf '  ]\n}\n'
} >"$result" || die "cannot write $result"
echo
log "wrote $result"
