#!/usr/bin/env bash
# Repeats the noise and outlier experiments of the G2S paper (Di Angelo & Giaccari 2011, §5,
# Tables 3 and 4) on the Stanford Bunny, and meshes the merged raw range scans of the same bunny:
# perturbs the cloud with `g2s synth --from`, meshes it with `g2s mesh`, measures the mesh with
# `g2s stats --points`, renders it with `g2s render`, and writes docs/robustness.md with the
# tables and docs/img/robustness/*.png. Builds g2s first if needed.
#   scripts/robustness.sh        (G2S_DATA_DIR: the scans, default ../shared/data;
#                                 G2S_BUILD_DIR: the build folder, default build)
# Exits 1 when any mesh has a non-manifold edge or vertex or an orientation conflict (the doc is
# still written, with the failures listed at its top).
set -euo pipefail
cd "$(dirname "$0")/.."
data=${G2S_DATA_DIR:-../shared/data}
build=${G2S_BUILD_DIR:-build}
bunny=$data/closed-bunny-zipper.ply
raw=$data/raw-bunny.ply
for f in "$bunny" "$raw"; do
  [ -f "$f" ] || { echo "robustness.sh: no $f (set G2S_DATA_DIR)" >&2; exit 3; }
done
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$build" -j"$(nproc)" --target g2s_cli
g2s=$build/g2s

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
img=docs/img/robustness
mkdir -p "$img"
rm -f "$img"/*.png
size=480x360
view=-30,15  # three-quarter view of the bunny's left side (its scans are y-up)

# The number after "KEY": in a one-line JSON object (the first one, so top-level keys win).
field() { grep -o "\"$2\": *[-0-9.eE+]*" <<<"$1" | head -n1 | sed 's/.*: *//'; }
percent() { awk -v x="$1" 'BEGIN { printf "%.2f%%", 100 * x }'; }

failures=()
declare -A row  # name -> table cells after the label
declare -A largest_row  # name -> cells for the largest piece alone
declare -A stat # name,key -> number, for the discussion

# measure NAME CLOUD: meshes CLOUD, measures and renders the mesh, fills row[NAME] and stat.
measure() {
  local name=$1 cloud=$2 mesh_json stats_json largest_json
  mesh_json=$("$g2s" mesh "$cloud" -o "$work/$name.ply" --json --no-stats)
  stats_json=$("$g2s" stats "$work/$name.ply" --points "$cloud" --json | tr -d ' \n')
  "$g2s" render "$work/$name.ply" -o "$img/$name.png" --size $size --view=$view --up y \
    --edge-width "${edge_width:-2}" 2>/dev/null
  local k
  for k in triangles non_manifold_vertices non_manifold_edges holes boundary_edges \
           orientation_conflicts components vertices input_points covered_points coverage; do
    stat[$name,$k]=$(field "$stats_json" "$k")
  done
  largest_json=$("$g2s" stats "$work/$name.ply" --largest-component --json | tr -d ' \n')
  for k in triangles holes boundary_edges vertices; do
    stat[$name,largest_$k]=$(field "$largest_json" "$k")
  done
  largest_row[$name]="${stat[$name,largest_triangles]} | ${stat[$name,largest_holes]} | ${stat[$name,largest_boundary_edges]} | $(( ${stat[$name,components]} - 1 )) | $(( ${stat[$name,triangles]} - ${stat[$name,largest_triangles]} ))"
  stat[$name,seconds]=$(field "$mesh_json" seconds)
  stat[$name,removed]=$(field "$mesh_json" triangles_removed)
  if [ "${stat[$name,non_manifold_vertices]}" != 0 ] || [ "${stat[$name,non_manifold_edges]}" != 0 ] ||
     [ "${stat[$name,orientation_conflicts]}" != 0 ]; then
    failures+=("$name: ${stat[$name,non_manifold_edges]} non-manifold edges, ${stat[$name,non_manifold_vertices]} non-manifold vertices, ${stat[$name,orientation_conflicts]} orientation conflicts")
    # Keep what reproduces it: the cloud (g2s mesh it) and the mesh, in out/ (not committed).
    mkdir -p out/robustness
    cp "$cloud" "out/robustness/$name-cloud.ply"
    cp "$work/$name.ply" "out/robustness/$name-mesh.ply"
    failures[-1]+=" (out/robustness/$name-cloud.ply)"
  fi
  row[$name]="${stat[$name,input_points]} | ${stat[$name,triangles]} | ${stat[$name,non_manifold_vertices]} | ${stat[$name,holes]} | ${stat[$name,boundary_edges]} | ${stat[$name,non_manifold_edges]} | ${stat[$name,orientation_conflicts]} | ${stat[$name,components]} | $(percent "${stat[$name,coverage]}") | ${stat[$name,removed]} | ${stat[$name,seconds]}"
  echo "robustness.sh: $name: ${row[$name]}" >&2
}

# perturb NAME NOISE OUTLIERS: the bunny with noise and outliers (seed 1), measured.
perturb() {
  local name=$1
  "$g2s" synth --from "$bunny" --noise "$2" --outliers "$3" --seed 1 -o "$work/$name-cloud.ply" \
    2>"$work/$name-synth.txt"
  measure "$name" "$work/$name-cloud.ply"
}

measure clean "$bunny"
perturb noise-0.1 0.1 0
perturb noise-0.2 0.2 0
perturb noise-0.5 0.5 0
perturb outliers-5 0 0.05
perturb outliers-10 0 0.10
perturb outliers-20 0 0.20
edge_width=1 measure raw "$raw"  # 1-pixel edges: there are tens of thousands
spacing=$(grep -o 'spacing [0-9.e-]*' "$work/noise-0.1-synth.txt" | cut -d' ' -f2)

# Outlier rows: where the outliers went. The bunny's own points are the clean cloud's, unchanged,
# so stats --points on the clean cloud counts the bunny points among a mesh's vertices; the rest
# of the vertices are outliers.
declare -A outlier_row
for name in outliers-5 outliers-10 outliers-20; do
  all_json=$("$g2s" stats "$work/$name.ply" --points "$bunny" --json | tr -d ' \n')
  piece_json=$("$g2s" stats "$work/$name.ply" --points "$bunny" --largest-component --json |
    tr -d ' \n')
  added=$(( ${stat[$name,input_points]} - ${stat[clean,input_points]} ))
  used=$(( ${stat[$name,vertices]} - $(field "$all_json" covered_points) ))
  piece_bunny=$(field "$piece_json" covered_points)
  in_piece=$(( $(field "$piece_json" vertices) - piece_bunny ))
  stat[$name,piece_bunny]=$piece_bunny
  stat[$name,in_piece]=$in_piece
  stat[$name,in_stray]=$(( used - in_piece ))
  stat[$name,left_out]=$(( added - used ))
  stat[$name,stray]=$(( ${stat[$name,components]} - 1 ))
  outlier_row[$name]="$added | $piece_bunny of ${stat[clean,input_points]} | $in_piece | ${stat[$name,in_stray]} | ${stat[$name,left_out]}"
done

picture_row() {
  local out="|" name
  for name in "$@"; do out+=" ![$name](img/robustness/$name.png) |"; done
  echo "$out"
}

header="| points | triangles NT | non-manifold vertices n_nmv | holes n_h | boundary edges n_be | non-manifold edges | orientation conflicts | components | coverage | removed by the non-manifold pass | seconds |"
rule="|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
commit=$(git rev-parse --short HEAD)
git diff --quiet HEAD -- src include tools 2>/dev/null || commit="$commit (with local changes)"
cpu=$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //' || echo unknown)

if [ ${#failures[@]} -eq 0 ]; then
  verdict="**No mesh has a non-manifold edge, a non-manifold vertex or an orientation conflict.**"
else
  verdict="**DEFECTS FOUND — the mesher's guarantee is broken in these cases:** $(printf '%s; ' "${failures[@]}")"
fi

cat > docs/robustness.md <<EOF
# Noise and outliers: the paper's Tables 3 and 4 on the Stanford Bunny

<!-- Written by scripts/robustness.sh: edit the script, not this file. -->
Regenerate this page, its tables and its pictures with

    scripts/robustness.sh

(\`G2S_DATA_DIR\` for the scans, default \`../shared/data\`; it builds \`g2s\` first if needed).
Last run: g2s $commit, default mesher options, on $(nproc) cores ($cpu), a machine shared with
other jobs, so seconds are indicative.

$verdict

## What is measured
The paper (Di Angelo & Giaccari 2011, §5) tests robustness on the Stanford Bunny twice: with
Gaussian noise at three values of its standard deviation σ (its Table 3, Fig. 8) and with 5%,
10% and 20% outliers (its Table 4, Fig. 9), counting non-manifold vertices n_nmv, holes n_h and
boundary edges n_be. We do the same on \`closed-bunny-zipper.ply\` (the 35,947 vertices of Stanford's
zippered bunny; see the README beside the scans), and mesh the ten merged raw range scans
\`raw-bunny.ply\` as they are: real scanner noise, overlapping layers, no synthetic help.

- **Noise**: \`g2s synth --from bunny --noise S\` adds S·s·N(0, 1) independently to x, y and z of
  every point, where s = $spacing m is the cloud's exact mean nearest-neighbour distance. So
  σ = 0.5 moves a point by √3·σ ≈ 0.87 s (root mean square), about 0.9 mm: some three times the
  distance between the overlapping raw scans of this bunny (median 0.23–0.34 mm, data README).
- **Outliers**: \`--outliers F\` appends round(F·n) points uniform in the cloud's bounding box.
- Both are drawn from a counter-based generator per point (seed 1): the clouds are the same on
  every machine and thread count. \`g2s mesh\` then meshes each cloud with its defaults,
  \`g2s stats --points CLOUD\` measures it (definitions: \`docs/algorithm.md\`, docs/algorithm.md §9),
  and \`g2s render\` draws it.
- *coverage*: share of the cloud's points that are mesh vertices; *removed by the non-manifold
  pass*: triangles the clean-up (paper §4.1) deleted to make every vertex manifold; *seconds*:
  reading the cloud to the written mesh.

## Noise (the paper's Table 3)

| σ / s $header
|---$rule
| 0 (clean) | ${row[clean]} |
| 0.1 | ${row[noise-0.1]} |
| 0.2 | ${row[noise-0.2]} |
| 0.5 | ${row[noise-0.5]} |

| clean | σ = 0.1 s | σ = 0.2 s | σ = 0.5 s |
|---|---|---|---|
$(picture_row clean noise-0.1 noise-0.2 noise-0.5)

## Outliers (the paper's Table 4)

| outliers $header
|---$rule
| 0 (clean) | ${row[clean]} |
| 5% | ${row[outliers-5]} |
| 10% | ${row[outliers-10]} |
| 20% | ${row[outliers-20]} |

Where the outliers went. The bunny's own points are those of the clean cloud, unchanged, so
\`g2s stats --points\` on the clean cloud tells them from the outliers; *the bunny* is the
mesh's largest piece (\`g2s stats --largest-component\`), the other pieces are stray patches.

| outliers | points added | bunny points in the bunny | outliers in the bunny's surface | outliers in stray patches | outliers left out |
|---|---:|---:|---:|---:|---:|
| 5% | ${outlier_row[outliers-5]} |
| 10% | ${outlier_row[outliers-10]} |
| 20% | ${outlier_row[outliers-20]} |

| clean | 5% | 10% | 20% |
|---|---|---|---|
$(picture_row clean outliers-5 outliers-10 outliers-20)

## Merged raw range scans

| cloud $header
|---$rule
| raw-bunny (10 scans) | ${row[raw]} |

| clean zippered bunny | raw range scans |
|---|---|
$(picture_row clean raw)

## The largest piece alone
Stray patches add their own boundary edges and holes (a lone triangle has 3 and 1). Measured on
the largest piece only (\`g2s stats --largest-component\`), the counts are those of the bunny's
surface, the closest to what the paper's tables count:

| cloud | triangles | holes n_h | boundary edges n_be | other pieces | triangles in them |
|---|---:|---:|---:|---:|---:|
| clean | ${largest_row[clean]} |
| σ = 0.1 s | ${largest_row[noise-0.1]} |
| σ = 0.2 s | ${largest_row[noise-0.2]} |
| σ = 0.5 s | ${largest_row[noise-0.5]} |
| 5% outliers | ${largest_row[outliers-5]} |
| 10% outliers | ${largest_row[outliers-10]} |
| 20% outliers | ${largest_row[outliers-20]} |
| raw range scans | ${largest_row[raw]} |

Pictures: \`g2s render MESH --size $size --view=$view --up y\` (raw scans: \`--edge-width 1\`, as
their boundary edges would hide the surface at 2 pixels); outside blue, inside yellow (seen
through a hole, or where the surface folds back), boundary edges red, non-manifold edges magenta
(there are none).

## The pictures
\`g2s render\` (\`src/render/\`) is our own: an orthographic z-buffer rasteriser with flat shading
and a PNG encoder with its own deflate (fixed Huffman codes after LZ77), about 600 lines and no
library. We preferred it to a Debian tool: the mesh viewers that can save a picture (MeshLab,
ParaView, Blender) are large installs that need an X server or xvfb to run offscreen, and each
would need a script of its own to colour boundary and non-manifold edges as \`g2s stats\` defines
them. Ours draws exactly the edges \`g2s stats\` counts, gives the same bytes for the same mesh,
and is tested in the suite (\`tests/render/render_test.cpp\` reads its PNGs back with an independent
decoder). Shading is quantised to 64 levels so every picture fits a PNG palette: about 45 KB at
480×360.

## Discussion
- **Manifold in every case.** Non-manifold edges, non-manifold vertices and orientation
  conflicts are 0 for every noise level, every outlier share and the raw scans. Edges are
  manifold by construction (the Point-Edge Map never gives an edge a third triangle); vertices are
  made manifold by the clean-up pass, which had to remove ${stat[noise-0.5,removed]} triangles at σ = 0.5 s
  and ${stat[outliers-20,removed]} with 20% outliers (${stat[clean,removed]} on the clean cloud).
  \`tests/data/robustness_test.cpp\` keeps the two hardest cases so.
- **Noise.** G2S interpolates: every point stays a vertex where it was (coverage
  $(percent "${stat[noise-0.5,coverage]}") even at σ = 0.5 s), so the noise is in the surface, as the
  pictures show; nothing is smoothed. Up to σ = 0.2 s the mesh is hardly affected
  (${stat[noise-0.2,holes]} holes and ${stat[noise-0.2,boundary_edges]} boundary edges, against ${stat[clean,holes]} and ${stat[clean,boundary_edges]} on the clean cloud). At σ = 0.5 s
  points are displaced by about their spacing and the surface is no longer locally flat, which
  is what G2S assumes: the mesh keeps ${stat[noise-0.5,holes]} small holes (${stat[noise-0.5,boundary_edges]} boundary edges), and the
  non-manifold pass had to remove ${stat[noise-0.5,removed]} triangles.
- **Outliers.** The bunny itself is barely touched: its largest piece holds
  ${stat[outliers-20,piece_bunny]} of the ${stat[clean,input_points]} bunny points even with 20% outliers and has ${stat[outliers-20,largest_holes]} holes
  (${stat[clean,largest_holes]} clean); ${stat[outliers-20,in_piece]} outliers close to the surface became vertices of it.
  The other outliers are either left out (${stat[outliers-20,left_out]} at 20%) or meshed among themselves into
  small stray patches (${stat[outliers-20,in_stray]} outliers in ${stat[outliers-20,stray]} patches at 20%, the scattered triangles
  in the pictures), and these patches carry most of the boundary edges and holes of the
  whole-mesh table. The mesher has no
  notion of an outlier: three outliers whose smallest ball is empty make a valid Gabriel
  triangle. Dropping small pieces (or points without close neighbours) would clear them; the
  mesher does not do it today.
- **Raw scans.** Ten overlapping noisy layers are the hardest input here: the mesh has
  ${stat[raw,holes]} holes and ${stat[raw,boundary_edges]} boundary edges where the layers disagree, but still no non-manifold
  edge or vertex, and it covers $(percent "${stat[raw,coverage]}") of the 362,272 points.

## Comparison with the paper
The copy of the paper we have (text extracted from the PDF) has lost the
numbers of Tables 3 and 4 and the σ values of Fig. 8 (their cells are empty), so only its stated
findings can be compared, not its figures:
- "Neither does the new version of G2S generate any non manifold vertices" (with noise and with
  outliers): **reproduced**, 0 in every case above, and 0 non-manifold edges and orientation
  conflicts as well.
- With noise, the new G2S "produces more defectiveness than the Robust Cocone and the Ball
  Pivoting" at the larger σ, "since it does not perform the smoothing of points", but keeps the
  details: **consistent** — holes and boundary edges grow sharply at σ = 0.5 s while every point
  stays a vertex. We have no Cocone or Ball Pivoting run to compare counts with.
- "With a low percentage, up to 5%, the tessellation obtained by means of the G2S_new is not
  significantly affected by the presence of outliers": **consistent** on the bunny's own
  surface — its largest piece has ${stat[outliers-5,largest_holes]} holes and ${stat[outliers-5,largest_boundary_edges]} boundary edges at 5% (${stat[clean,largest_holes]} and
  ${stat[clean,largest_boundary_edges]} clean), ${stat[outliers-20,largest_holes]} and ${stat[outliers-20,largest_boundary_edges]} at 20%. Counted over the whole mesh, the stray patches of meshed
  outliers dominate (${stat[outliers-5,holes]} holes at 5%, ${stat[outliers-20,holes]} at 20%); the paper's text does not say whether
  its counts include such patches. Its other finding, defects "comparable with those produced by
  the Ball Pivoting method" above 5%, needs a Ball Pivoting run we do not have.
- Our σ is in units of the mean spacing (the issue's choice), the paper's is not stated in the
  copy we have; our bunny is Stanford's 35,947-point zippered model, which may differ from the
  paper's cloud.
EOF
echo "robustness.sh: wrote docs/robustness.md and $(ls "$img" | wc -l) pictures ($(du -ch "$img"/*.png | tail -n1 | cut -f1))" >&2
if [ ${#failures[@]} -gt 0 ]; then
  printf 'robustness.sh: %s\n' "${failures[@]}" >&2
  exit 1
fi
