#!/usr/bin/env bash
# scripts/stems.sh: one stem per operation. For every operation, the files `git ls-files` holds
# under its name in each tree: public header, host code, kernel, scalar reference, tests and CLI
# command; a missing one is printed as MISSING and makes the exit status 1, as does an operation's
# source (src/ops/, testing/ excepted) that includes another operation's internal header
# (src/ops/OTHER_*.hpp): what operations share lives in src/core/. An operation with
# no kernel of its own (it runs another's: the horizon lists run the scalar hull tree on the
# host, sun shading the horizon sweep) or no reference (the sun's position is checked against
# published tables, not a mirror) says so in the table below instead of a path pattern.
#
#   scripts/stems.sh          the table, and the exit status
set -euo pipefail
cd "$(dirname "$0")/.."
files=$(git ls-files)
status=0
# stem | kernel (- for none, with the reason) | reference (- likewise) [| CLI: - and why, when it has none yet]
stems=(
  "horizon|kernels/horizon.cl|testing/horizon_reference.cpp"
  "sky_view_factor|kernels/shared/sky_view_factor.cl|testing/sky_view_factor_reference.cpp"
  "ambient_occlusion|kernels/shared/ambient_occlusion.cl|testing/ambient_occlusion_reference.cpp"
  "environment_light|kernels/environment_light.cl|testing/environment_light_reference.cpp"
  "sun_shading|- (the horizon sweep in the sun's azimuth)|testing/sun_shading_reference.cpp"
  "insolation|kernels/insolation.cl|testing/insolation_reference.cpp"
  "intervisibility|kernels/intervisibility.cl|testing/intervisibility_reference.cpp"
  "horizon_lists|- (the scalar hull tree on the host)|testing/horizon_lists_reference.cpp"
  "bounce|kernels/bounce.cl|testing/bounce_reference.cpp"
  "viewshed|kernels/viewshed.cl|testing/viewshed_reference.cpp"
  "sun|- (host arithmetic)|- (published positions: Reda & Andreas 2004, the USNO)"
  "region_visibility|kernels/region_visibility.cl|testing/region_visibility_reference.cpp"
  "pvs|kernels/pvs.cl|testing/pvs_reference.cpp"
)
has() { grep -qx "$1" <<< "$files"; }
show() {  # label, path or "- reason"
  if [[ $2 == -* ]]; then
    printf '  %-10s none %s\n' "$1" "${2#- }"
  elif has "$2"; then
    printf '  %-10s %s\n' "$1" "$2"
  else
    printf '  %-10s MISSING %s\n' "$1" "$2"
    status=1
  fi
}
for entry in "${stems[@]}"; do
  IFS='|' read -r stem kernel reference cli <<< "$entry"
  echo "$stem"
  show header "include/hfvis/$stem.hpp"
  show host "src/ops/$stem.cpp"
  show kernel "$kernel"
  show reference "$reference"
  # Its tests: test_STEM.cpp and test_STEM_PART.cpp, but not another stem's (test_horizon_lists is not horizon's).
  tests=""
  for t in $(grep -E "^tests/test_${stem}(_[a-z_]+)?\.cpp$" <<< "$files" || true); do
    other=0
    for e in "${stems[@]}"; do [[ ${e%%|*} != "$stem" && $t == "tests/test_${e%%|*}.cpp" ]] && other=1; done
    ((other)) || tests+="$t "
  done
  if [[ -n $tests ]]; then printf '  %-10s %s\n' tests "$tests"; else show tests "tests/test_$stem.cpp"; fi
  show cli "${cli:-cli/commands/$stem.cpp}"
done
# Internal headers by operation: src/ops/STEM.hpp or src/ops/STEM_*.hpp, the longest stem that fits.
stem_of() {
  local name best=""
  name=$(basename "$1" .cpp)
  name=${name%.hpp}
  for e in "${stems[@]}"; do
    local s=${e%%|*}
    [[ ($name == "$s" || $name == "$s"_*) && ${#s} -gt ${#best} ]] && best=$s
  done
  echo "$best"
}
echo "includes of another operation's internals (src/ops/):"
crossings=0
for f in $(grep -E '^src/ops/[a-z_]+\.(cpp|hpp)$' <<< "$files"); do
  own=$(stem_of "$f")
  for inc in $(grep -oE '#include "ops/[a-z_]+\.hpp"' "$f" | sed -E 's/#include "ops\/(.*)"/\1/'); do
    other=$(stem_of "$inc")
    if [[ -n $other && $other != "$own" ]]; then
      echo "  $f includes ops/$inc (${other}'s)"
      crossings=1
    fi
  done
done
((crossings)) && status=1 || echo "  none"
exit $status
