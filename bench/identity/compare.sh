#!/usr/bin/env bash
# Output identity between two builds of the vitri command (issue 40's proof for refactors that must not
# change a single output byte): runs the same cases with BASE and NEW and compares every file with cmp.
# Usage: bash bench/identity/compare.sh BASE_VITRI NEW_VITRI OUTDIR [--large]
#   --large adds the 10^6-point runs (sampled from the shared elephant; minutes each on 2 cores).
# Prints one line per case (same / DIFFERENT, seconds of each) and exits 1 when any output differs.
# The base's outputs are kept in OUTDIR/base and reused when the same BASE is given again.
set -uo pipefail
base=$(readlink -f "$1"); new=$(readlink -f "$2"); out=$3; large=${4:-}
root=$(cd "$(dirname "$0")/../.." && pwd)
shared=$root/../shared/data
mkdir -p "$out/base" "$out/new" "$out/inputs"
# An edit script touching add / move / value / remove and writes between them.
cat > "$out/inputs/edits.txt" <<'EDITS'
add 0.01 0.02 0.03 -0.5
write @DIR@/edit-1.obj
move 3 0.05 0.04 0.02
value 5 0.02
write @DIR@/edit-2.obj
remove 7
remove 0
write @DIR@/edit-3.obj
EDITS
cases=(
  "hand|$root/data/hand.off|--precision 0.02 --precision 0.01"
  "bunny-global|$root/data/bunny.off|--function global --precision 0.01"
  "bunny-local|$root/data/bunny.off|--function local"
  "knot|$root/data/knot1.off|"
  "elephant|$root/data/elephant.off|--precision 0.005"
  "pig-quality|$root/data/pig.off|--precision 0.01 --min-angle 30"
  "hand-quality|$root/data/hand.off|--precision 0.02 --min-angle 30"
  "knot-quality|$root/data/knot1.off|--precision 0.01 --min-angle 25"
  "sphere926|$root/data/sphere926.pwn|"
  "sphere20k|$root/data/sphere_20k.xyz|"
  "hippo-scan|$root/data/hippo1_view.xyz|"
  "lidar-cars|$root/data/lidar_cars.xyz|"
  "rgbd-box|$shared/scans/rgbd_tabletop_box.xyz|"
  "fandisk-threads1|$shared/fandisk_large.off|--threads 1"
  "fandisk-threads2|$shared/fandisk_large.off|--threads 2"
  "hand-edits|$root/data/hand.off|--precision 0.02 --edits @EDITS@"
  "bunny-local-edits|$root/data/bunny.off|--function local --precision 0.01 --edits @EDITS@"
)
if [ "$large" = "--large" ]; then
  if [ ! -f "$out/inputs/elephant-1e6.xyz" ]; then
    # Pure Python (no numpy on every machine): area-weighted uniform samples of the triangles, with the
    # face normals, seeded.
    python3 - "$shared/elephant.off" "$out/inputs/elephant-1e6.xyz" <<'PY' || exit 2
import random, sys
tok = open(sys.argv[1]).read().split()
assert tok[0] == "OFF"; nv, nf = int(tok[1]), int(tok[2]); k = 4
V = [tuple(float(x) for x in tok[k + 3 * i:k + 3 * i + 3]) for i in range(nv)]; k += 3 * nv
F = [tuple(int(x) for x in tok[k + 4 * i + 1:k + 4 * i + 4]) for i in range(nf)]
sub = lambda a, b: (a[0] - b[0], a[1] - b[1], a[2] - b[2])
cross = lambda a, b: (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
N, A = [], []
for f in F:
    n = cross(sub(V[f[1]], V[f[0]]), sub(V[f[2]], V[f[0]])); l = sum(c * c for c in n) ** 0.5
    A.append(l); N.append(tuple(c / (l + 1e-300) for c in n))
rng = random.Random(7)
with open(sys.argv[2], "w") as out:
    for t in rng.choices(range(nf), weights=A, k=10**6):
        u, v = rng.random(), rng.random()
        if u + v > 1: u, v = 1 - u, 1 - v
        a, b, c = (V[i] for i in F[t]); n = N[t]
        p = [a[j] + u * (b[j] - a[j]) + v * (c[j] - a[j]) for j in range(3)]
        out.write("%.9g %.9g %.9g %.9g %.9g %.9g\n" % (p[0], p[1], p[2], n[0], n[1], n[2]))
PY
  fi
  cases+=("elephant-1e6|$out/inputs/elephant-1e6.xyz|")
fi
status=0
for c in "${cases[@]}"; do
  IFS='|' read -r name input args <<<"$c"
  if [ ! -f "$input" ]; then printf '%-20s %s\n' "$name" "MISSING INPUT $input"; status=1; continue; fi
  for side in base new; do
    exe=$base; [ $side = new ] && exe=$new
    dir=$out/$side/$name
    if [ $side = base ] && [ -f "$dir/.done" ] && [ "$(cat "$dir/.done")" = "$base" ]; then continue; fi
    rm -rf "$dir"; mkdir -p "$dir"
    sed "s#@DIR@#$dir#g" "$out/inputs/edits.txt" > "$dir/edits.txt"
    a=${args//@EDITS@/$dir/edits.txt}
    t0=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$exe" mesh "$input" -o "$dir/out.obj" $a -q > "$dir/log.txt" 2>&1
    echo "rc=$?" >> "$dir/log.txt"
    awk -v a="$(date +%s.%N)" -v b="$t0" 'BEGIN { printf "%.2f\n", a - b }' > "$dir/seconds"
    [ $side = base ] && echo "$base" > "$dir/.done"
  done
  b=$out/base/$name; n=$out/new/$name; same=same
  for f in $(cd "$b" && ls | grep -v -e '^log.txt$' -e '^seconds$' -e '^edits.txt$'); do
    cmp -s "$b/$f" "$n/$f" || { same="DIFFERENT ($f)"; status=1; }
  done
  [ "$(tail -1 "$b/log.txt")" = "$(tail -1 "$n/log.txt")" ] || { same="DIFFERENT (exit status)"; status=1; }
  printf '%-20s %-28s base %6.1f s  new %6.1f s\n' "$name" "$same" "$(cat "$b/seconds")" "$(cat "$n/seconds")"
done
exit $status
