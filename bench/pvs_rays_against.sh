#!/usr/bin/env bash
# bench/pvs_rays_against.sh: the PVS ray caster's rays per second (`hfvis_bench pvs-rays`: 1024^2
# city and rough terrain, rays from the view band) of this build against another hfvis_bench
# (an earlier commit's build), the two run alternately in one go so that both see the same load
# on a shared machine. Prints every run's rows, then per field and column the median of each and
# their ratio (this build over the other). Each run is the fastest of --reps casts per mode (2: a
# build whose warm-up does not allocate a full launch's buffers pays for that in its first cast).
#
#   bench/pvs_rays_against.sh OTHER_HFVIS_BENCH [--rounds 3] [--rays 1000000] [--reps 2]
#   BUILD_DIR=... selects this build (default build/).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[[ $# -ge 1 && $1 != -h && $1 != --help ]] || { sed -n '2,10p' "$0"; exit 0; }
other=$1
shift
rounds=3
rays=1000000
reps=2
while [[ $# -gt 0 ]]; do
  case "$1" in
    --rounds) rounds=$2; shift ;;
    --rays) rays=$2; shift ;;
    --reps) reps=$2; shift ;;
    *) echo "pvs_rays_against.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
this=${BUILD_DIR:-$root/build}/bench/hfvis_bench
for b in "$this" "$other"; do [[ -x $b ]] || { echo "pvs_rays_against.sh: no executable $b" >&2; exit 1; }; done
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$root/bench/out/pocl-cache}
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
echo "<!-- bench/pvs_rays_against.sh $other --rounds $rounds --rays $rays --reps $reps; $(date -u +%Y-%m-%dT%H:%MZ), commit $(git -C "$root" rev-parse --short HEAD) -->"
echo
echo "| run | build | field | rays/s (hit only) | rays/s (with view cells) | per CPU second (hit only) | (with view cells) |"
echo "| ---: | --- | --- | ---: | ---: | ---: | ---: |"
for ((r = 1; r <= rounds; ++r)); do
  for which in this other; do
    bench=$this
    [[ $which == other ]] && bench=$other
    "$bench" pvs-rays --size 1024 --rays "$rays" --reps "$reps" city noise | grep '^| [a-z]* [0-9]*x[0-9]* |' |
      awk -F'|' -v r="$r" -v w="$which" '{gsub(/ /, "", $2); gsub(/[ M]/, "", $5); gsub(/[ M]/, "", $6);
        gsub(/[ M]/, "", $7); gsub(/[ M]/, "", $8); print r, w, $2, $5, $6, $7, $8}' >> "$rows"
  done
done
awk '{printf "| %s | %s | %s | %.2fM | %.2fM | %.2fM | %.2fM |\n", $1, $2, $3, $4, $5, $6, $7}' "$rows"
echo
echo "Medians over $rounds rounds (this build / the other):"
echo
echo "| field | rays/s (hit only) | rays/s (with view cells) | per CPU second (hit only) | (with view cells) |"
echo "| --- | ---: | ---: | ---: | ---: |"
for field in $(awk '{print $3}' "$rows" | sort -u); do
  line="| $field |"
  for col in 4 5 6 7; do
    a=$(awk -v f="$field" -v c="$col" '$2 == "this" && $3 == f {print $c}' "$rows" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}')
    b=$(awk -v f="$field" -v c="$col" '$2 == "other" && $3 == f {print $c}' "$rows" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}')
    line+=" $(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.2fM / %.2fM = %.2fx", a, b, a / b}') |"
  done
  echo "$line"
done
echo
echo "(each run: \`hfvis_bench pvs-rays --size 1024 --rays $rays --reps $reps city noise\`: the fastest of $reps casts per mode on one caster)"
