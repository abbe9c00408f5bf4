#!/usr/bin/env bash
# Tries the CLI on hostile input and prints, as a Markdown table, what each case gets: the
# exit status (0 success, 1 a run error, 2 a usage error), the first line of the error and
# whether the run left the input intact and wrote no output. docs/BAD_INPUT.md holds this
# table; the test BadInputTableIsCurrent regenerates it and fails when the two differ.
#
#   scripts/bad_input.sh [HFVIS]                   print the table (HFVIS default build/hfvis)
#   scripts/bad_input.sh --check DOC.md [HFVIS]    compare with the table in DOC.md: every case,
#                                                  command, status and the last column must match
#                                                  (the error text is the program's, printed for
#                                                  people; it may name device figures)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
check=""
if [[ ${1:-} == --check ]]; then
  check=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
  shift 2
fi
if [[ -n $check ]]; then
  fresh=$(bash "$0" "$@")
  # The CLI table: from its "| case | command" header to the first line not in the table.
  columns() {
    awk -F ' [|] ' '/^[|] case [|] command/ { on = 1 } on && !/^[|]/ { exit } on { print $1 " | " $2 " | " $3 " | " $NF }'
  }
  if ! diff <(columns < "$check") <(columns <<< "$fresh"); then
    echo "bad_input.sh: $check is not what the CLI does now (< the document, > now); regenerate it:" >&2
    echo "  scripts/bad_input.sh > table, and paste it into $check" >&2
    exit 1
  fi
  empty=$(awk -F ' [|] ' '$3 != "0" && $3 != "status" && $3 != "---:" && $4 == ""' <<< "$fresh")
  [[ -z $empty ]] || { echo "bad_input.sh: failures without an error message:" >&2; echo "$empty" >&2; exit 1; }
  exit 0
fi
hfvis=$(cd "$(dirname "${1:-$root/build/hfvis}")" && pwd)/$(basename "${1:-$root/build/hfvis}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

# Inputs: a good field, and bad ones.
cp "$root/data/sine_256.exr" field.exr
cp "$root/data/clear_sky.exr" sky.exr
printf 'not an image' > garbage.exr
: > empty.exr
head -c 1000 field.exr > truncated.exr
mkdir -p folder.exr out
python3 - << 'PY'
import struct, zlib
# A two-channel float EXR would need OpenEXR; a 16-bit two-channel PNG is written by hand.
def png(path, w, h, channels, rows):
    color = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    raw = b"".join(b"\0" + b"".join(struct.pack(">H", v) for v in row) for row in rows)
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, color, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
png("two_channels.png", 4, 3, 2, [[1, 2] * 4 for _ in range(3)])
png("mask_small.png", 4, 3, 1, [[1] * 4 for _ in range(3)])  # a pvs --view-mask of the wrong size
# A float field (PFM) with one height of 1e30: beyond what the kernels' float products hold.
values = [0.0] * 64
values[3 * 8 + 4] = 1e30
with open("huge.pfm", "wb") as f:
    f.write(b"Pf\n8 8\n-1.0\n" + struct.pack("<64f", *values))
PY
# Environment maps with a negative and a non-finite radiance (2:1, one channel).
/usr/bin/python3 - "$root/data" << 'PY'
import sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import make_data
make_data.write_exr_builtin("negative.exr", -np.ones((8, 16)), {})
nan = np.ones((8, 16))
nan[3, 5] = np.nan
make_data.write_exr_builtin("nan.exr", nan, {})
PY
# A GeoTIFF of the field (no georeference: only its name matters here).
"$hfvis" svf field.exr -o field.tif -k 1 -q
# An earlier PVS run's sets (pvs --resume), on the default grid.
"$hfvis" pvs field.exr -o prev_pvs.json --bitset prev_pvs.bin --samples 100 -q
mkfifo pipe.exr
printf '1,1\n2,2,-5\n' > negative_height.csv
printf '1,1\n%s\n' "$(head -c 5000 /dev/zero | tr '\0' 'x')" > long_line.csv
printf 'col,row,height\n1,1,2\n3,x,2\n' > bad_sources.csv
printf '1,1\n300,2\n' > outside_sources.csv
printf '5,3\n' > nodata_source.csv  # nan.exr's NaN
printf 'ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 abc 6\n' > words.asc
# An earlier result, write-protected by its owner (mode 0444).
cp field.tif protected.tif
chmod 444 protected.tif
ln -s loop_b.exr loop_a.exr
ln -s loop_a.exr loop_b.exr
sum_before=$(cat field.exr field.tif protected.tif prev_pvs.bin | md5sum)

echo "| case | command | status | error (first line) | input intact, nothing written |"
echo "| --- | --- | ---: | --- | --- |"
# try CASE [VAR=VALUE] -- ARGS...: runs hfvis ARGS (with VAR=VALUE in its environment).
try() {
  local what=$1 env=$2; shift 3
  rm -rf out/*
  set +e
  if [[ -n $env ]]; then env "$env" "$hfvis" "$@" > stdout.txt 2> stderr.txt < /dev/null; else
    "$hfvis" "$@" > stdout.txt 2> stderr.txt < /dev/null; fi
  local status=$?
  set -e
  local message
  message=$(head -1 stderr.txt | sed 's/^hfvis: error: //; s/|/\\|/g')
  [[ $status == 0 ]] && message="(none: it runs)"
  local clean=yes
  [[ "$(cat field.exr field.tif protected.tif prev_pvs.bin | md5sum)" == "$sum_before" ]] || clean="NO: input changed"
  if [[ $status != 0 && -n "$(ls -A out)" ]]; then clean="NO: wrote $(ls -A out | tr '\n' ' ')"; fi
  local shown="hfvis${*:+ $*}"
  [[ -n $env ]] && shown="$env $shown"
  echo "| $what | \`$shown\` | $status | $message | $clean |"
}
# Files.
try "input missing" "" -- svf absent.exr -o out/o.exr
try "input is a directory" "" -- svf folder.exr -o out/o.exr
try "input empty" "" -- svf empty.exr -o out/o.exr
try "input not an image" "" -- svf garbage.exr -o out/o.exr
try "input truncated" "" -- svf truncated.exr -o out/o.exr
try "ASCII grid with a word for a height" "" -- svf words.asc -o out/o.exr -k 4
try "two channels, none chosen" "" -- svf two_channels.png -o out/o.exr
try "channel that is not there" "" -- svf field.exr -o out/o.exr --channel Z
try "output directory missing" "" -- svf field.exr -o nowhere/o.exr
try "output is a directory" "" -- svf field.exr -o out
try "output is the input" "" -- svf field.exr -o field.exr
try "output is the input by another path" "" -- svf field.exr -o ./out/../field.exr
try "GeoTIFF output is the GeoTIFF input" "" -- svf field.tif -o field.tif
try "GeoTIFF output is the input by another path" "" -- horizon field.tif -o out/h.tif --distance-out out/../field.tif
try "output format unknown" "" -- svf field.exr -o out/o.xyz
try "output an 8-bit image" "" -- horizon field.exr -o out/o.png -k 4
try "output write-protected" "" -- svf field.exr -o protected.tif -k 4
try "output where no file can be created" "" -- svf field.exr -o /proc/o.exr -k 4
try "output a loop of symbolic links" "" -- svf field.exr -o loop_a.exr -k 4
try "input is a device" "" -- svf /dev/zero -o out/o.exr -k 4
try "input is a FIFO" "" -- svf pipe.exr -o out/o.exr -k 4
try "preview not a PNG" "" -- svf field.exr -o out/o.exr --preview out/p.jpg
# Arguments.
try "no arguments" "" --
try "unknown command" "" -- paint field.exr -o out/o.exr
try "unknown option" "" -- svf field.exr -o out/o.exr --fast
try "option without its value" "" -- svf field.exr -o out/o.exr -k
try "no output" "" -- svf field.exr
try "zero directions" "" -- svf field.exr -o out/o.exr -k 0
try "negative directions" "" -- svf field.exr -o out/o.exr -k -3
try "directions not a number" "" -- svf field.exr -o out/o.exr -k many
try "directions beyond the limit" "" -- svf field.exr -o out/o.exr -k 100000000
try "samples per unit zero" "" -- svf field.exr -o out/o.exr --samples-per-unit 0
try "samples per unit NaN" "" -- svf field.exr -o out/o.exr --samples-per-unit nan
try "samples per unit infinite" "" -- svf field.exr -o out/o.exr --samples-per-unit inf
try "maximum error zero" "" -- svf field.exr -o out/o.exr --max-error 0
try "maximum error of 1 or more (SVF lies in 0..1)" "" -- ao field.exr -o out/o.exr --max-error 1
try "maximum error with -k" "" -- svf field.exr -o out/o.exr --max-error 0.01 -k 16
try "maximum error beyond 4096 directions" "" -- svf field.exr -o out/o.exr --max-error 1e-7
try "error tile without a maximum error" "" -- svf field.exr -o out/o.exr --error-tile 32
try "error tile not a whole number" "" -- svf field.exr -o out/o.exr --max-error 0.01 --error-tile 2.5
try "error tile negative" "" -- ao field.exr -o out/o.exr --max-error 0.01 --error-tile -8
try "error tile for the visible count" "" -- viewcount field.exr -o out/o.exr --max-error 0.1 --error-tile 32
try "error estimate output is the output" "" -- svf field.exr -o out/o.exr --error-out out/o.exr
try "error estimate output is the input" "" -- ao field.exr -o out/o.exr -k 8 --error-out field.exr
try "error estimate with one direction" "" -- svf field.exr -o out/o.exr -k 1 --error-out out/e.exr
try "viewcount: maximum error zero" "" -- viewcount field.exr -o out/o.exr --max-error 0
try "viewcount: maximum error of 1 or more (relative)" "" -- viewcount field.exr -o out/o.exr --max-error 1
try "viewcount: maximum error not finite" "" -- viewcount field.exr -o out/o.exr --max-error inf
try "maximum error below double's normal numbers" "" -- svf field.exr -o out/o.exr --max-error 5e-324
try "viewcount: maximum error with -k" "" -- viewcount field.exr -o out/o.exr --max-error 0.1 -k 16
try "viewcount: maximum error of the naive method" "" -- viewcount field.exr -o out/o.exr --max-error 0.1 --method naive
try "viewcount: maximum error beyond 4096 directions" "" -- viewcount field.exr -o out/o.exr --max-error 1e-7 --error-out out/e.exr
try "viewcount: error estimate with one direction" "" -- viewcount field.exr -o out/o.exr -k 1 --error-out out/e.exr
try "horizon: maximum error zero" "" -- horizon field.exr -o out/o.exr --max-error 0
try "horizon: maximum error of 90 degrees or more" "" -- horizon field.exr -o out/o.exr --max-error 90
try "horizon: maximum error not finite" "" -- horizon field.exr -o out/o.exr --max-error nan
try "horizon: maximum error with -k" "" -- horizon field.exr -o out/o.exr --max-error 1 -k 16
try "horizon: maximum error with an error tile" "" -- horizon field.exr -o out/o.exr --max-error 1 --error-tile 32
try "horizon: maximum error beyond 4096 directions" "" -- horizon field.exr -o out/o.exr --max-error 1e-7 --error-out out/e.exr
try "horizon: error estimate under 5 directions" "" -- horizon field.exr -o out/o.exr -k 4 --error-out out/e.exr
try "shade --env: maximum error zero" "" -- shade field.exr --env sky.exr -o out/o.exr --max-error 0
try "shade --env: maximum error with -k" "" -- shade field.exr --env sky.exr -o out/o.exr --max-error 0.1 -k 16
try "shade: maximum error without --env" "" -- shade field.exr --sun 100,30 -o out/o.exr --max-error 0.1
try "shade --env: error estimate without a maximum error" "" -- shade field.exr --env sky.exr -o out/o.exr --error-out out/e.exr
try "lines per unit (removed: every sweep runs one line through each pixel centre)" "" -- viewcount field.exr -o out/o.exr --lines-per-unit 2
try "refraction out of range" "" -- svf field.exr -o out/o.exr --refraction 2
try "curvature for the bounce (not supported)" "" -- bounce field.exr --radiance field.exr -o out/b.exr --curvature
try "maximum distance zero" "" -- viewcount field.exr -o out/o.exr --max-distance 0
try "maximum distance for the bounce (not supported)" "" -- bounce field.exr --radiance field.exr -o out/b.exr --max-distance 10
try "maximum distance too short for the field" "" -- svf field.exr -o out/o.exr --max-distance 1e-9
try "nodata not a number" "" -- svf field.exr -o out/o.tif --nodata none
try "nodata infinite" "" -- svf field.exr -o out/o.tif --nodata inf
try "nodata beyond float32" "" -- svf field.exr -o out/o.tif --nodata 1e39
try "nodata in hexadecimal" "" -- svf field.exr -o out/o.tif --nodata 0x10
try "nodata without a GeoTIFF output" "" -- svf field.exr -o out/o.exr --nodata -9999
try "nodata for the horizon lists (text)" "" -- horizons field.exr --at 3,3 -o out/h.json --nodata 0
try "nodata a value the output holds" "" -- viewshed field.tif -o out/o.tif --observer 3,3 --nodata 0
try "azimuth offset beyond a turn" "" -- svf field.exr -o out/o.exr --azimuth-offset 1e20
try "cell size beyond single precision" "" -- svf field.exr -o out/o.exr --cell-size 1e300
try "sun size negative" "" -- shade field.exr -o out/o.exr --sun 180,30 --sun-size -1
try "cell size zero" "" -- svf field.exr -o out/o.exr --cell-size 0
try "cell size negative" "" -- svf field.exr -o out/o.exr --cell-size 1,-2
try "cell size not a number" "" -- svf field.exr -o out/o.exr --cell-size 1,abc
try "z-scale zero" "" -- svf field.exr -o out/o.exr --z-scale 0
try "z-scale overflowing float" "" -- svf field.exr -o out/o.exr --z-scale 1e35
try "azimuth tolerance too large" "" -- horizon field.exr -o out/o.exr --azimuth-tolerance 10
try "azimuth tolerance for svf" "" -- svf field.exr -o out/o.exr --azimuth-tolerance 1
try "distance output for svf" "" -- svf field.exr -o out/o.exr --distance-out out/d.exr
try "unknown method" "" -- svf field.exr -o out/o.exr --method exact
try "memory budget too small" "" -- horizon field.exr -o out/o.exr --memory-budget 0.001
try "receiver outside the field" "" -- horizons field.exr --at 300,2 -o out/h.json
try "receiver not a pair" "" -- horizons field.exr --at 3 -o out/h.json
try "radiance of another size" "" -- bounce field.exr --radiance two_channels.png -o out/o.exr
try "shade without a sun" "" -- shade field.exr -o out/o.exr
try "shade given the sun two ways" "" -- shade field.exr -o out/o.exr --sun 180,30 --at 2026-06-21T12:00:00Z --lat 45 --lon 7
try "shade with a sun below the nadir" "" -- shade field.exr -o out/o.exr --sun 180,-95
try "environment map not 2:1" "" -- shade field.exr -o out/o.exr --env field.exr
try "environment map not an image" "" -- shade field.exr -o out/o.exr --env garbage.exr
try "environment map with two channels" "" -- shade field.exr -o out/o.exr --env two_channels.png
try "environment map with a negative radiance" "" -- shade field.exr -o out/o.exr --env negative.exr
try "environment map with a NaN radiance" "" -- shade field.exr -o out/o.exr --env nan.exr
try "environment map is the output" "" -- shade field.exr -o out/o.exr --env out/o.exr
try "albedo beyond 1" "" -- shade field.exr -o out/o.exr --sun 180,30 --albedo 1.5
try "insolation without a span" "" -- insolation field.exr -o out/o.exr --lat 45 --lon 7
try "insolation running backwards" "" -- insolation field.exr -o out/o.exr --lat 45 --lon 7 --from 2026-06-22T00:00:00Z --to 2026-06-21T00:00:00Z
try "insolation in steps of 0 minutes" "" -- insolation field.exr -o out/o.exr --lat 45 --lon 7 --from 2026-06-21T00:00:00Z --to 2026-06-22T00:00:00Z --step 0
try "viewshed without an observer" "" -- viewshed field.exr -o out/o.exr
try "viewshed observer outside the field" "" -- viewshed field.exr -o out/o.exr --observer 300,2
try "viewshed observer not a pair" "" -- viewshed field.exr -o out/o.exr --observer 3
try "viewshed observers file missing" "" -- viewshed field.exr -o out/o.exr --observers nowhere.csv
try "viewshed observers file not CSV" "" -- viewshed field.exr -o out/o.exr --observers garbage.exr
try "viewshed target below the surface" "" -- viewshed field.exr -o out/o.exr --observer 3,3 --target-height -1
try "viewshed observers file with an eye below the surface" "" -- viewshed field.exr -o out/o.exr --observers negative_height.csv
try "viewshed observers file with a 5000-byte line" "" -- viewshed field.exr -o out/o.exr --observers long_line.csv
try "viewshed observers file is a device" "" -- viewshed field.exr -o out/o.exr --observers /dev/zero
try "viewshed method unknown" "" -- viewshed field.exr -o out/o.exr --observer 3,3 --method stewart
try "viewshed cull level 0" "" -- viewshed field.exr -o out/o.exr --observer 3,3 --method culled --cull-level 0
try "viewshed cull level without culling" "" -- viewshed field.exr -o out/o.exr --observer 3,3 --cull-level 3
try "viewshed angle for several observers" "" -- viewshed field.exr -o out/o.exr --observer 3,3 --observer 4,4 --angle
try "arealight without a light" "" -- arealight field.exr -o out/o.exr
try "arealight with --light and --sources" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --sources bad_sources.csv
try "arealight light outside the field" "" -- arealight field.exr -o out/o.exr --light 250,0,256,4
try "arealight light not four numbers" "" -- arealight field.exr -o out/o.exr --light 1,1,4
try "arealight samples over the maximum" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --samples 4097
try "arealight sources file with a bad line" "" -- arealight field.exr -o out/o.exr --sources bad_sources.csv
try "arealight source outside the field" "" -- arealight field.exr -o out/o.exr --sources outside_sources.csv
try "arealight source on nodata" "" -- arealight nan.exr -o out/o.exr --sources nodata_source.csv
try "arealight viewsheds for a jittered light" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --method viewsheds
try "arealight bitmask for a light above the surface" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --method bitmask
try "arealight bitmask with decorrelation" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --absolute --light-height 100 --method bitmask --decorrelate
try "arealight masks an 8-bit image" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --masks out/m.png
try "arealight light image missing" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --light-image absent.exr
try "arealight light image with two channels" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --light-image two_channels.png
try "arealight light image with a negative value" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --light-image negative.exr
try "arealight light image with a NaN" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --light-image nan.exr
try "arealight light image over sources" "" -- arealight field.exr -o out/o.exr --sources outside_sources.csv --light-image field.exr
try "region without --to" "" -- region field.exr -o out/r.json --from 1,1,4,4
try "region rectangle outside the field" "" -- region field.exr -o out/r.json --from 1,1,4,4 --to 200,200,300,210
try "region output not JSON" "" -- region field.exr -o out/r.exr --from 1,1,4,4 --to 8,8,9,9
try "region rays not CSV" "" -- region field.exr -o out/r.json --from 1,1,4,4 --to 8,8,9,9 --rays out/r.txt
try "region heights beyond float range" "" -- region huge.pfm -o out/r.json --from 1,1,2,2 --to 5,5,6,6
try "arealight sources with a seed" "" -- arealight field.exr -o out/o.exr --sources nodata_source.csv --seed 7
try "arealight sources decorrelated" "" -- arealight field.exr -o out/o.exr --sources nodata_source.csv --decorrelate
try "arealight memory budget" "" -- arealight field.exr -o out/o.exr --light 1,1,4,4 --memory-budget 64
try "region memory budget" "" -- region field.exr -o out/r.json --from 1,1,4,4 --to 8,8,9,9 --memory-budget 64
try "arealight heights beyond float range" "" -- arealight huge.pfm -o out/o.exr --light 1,1,2,2
try "pvs heights beyond float range" "" -- pvs huge.pfm -o out/p.json --samples 10 --view-cell 4 --tile 2
try "pvs view cell 0" "" -- pvs field.exr -o out/p.json --samples 10 --view-cell 0
try "pvs view cell larger than the field" "" -- pvs field.exr -o out/p.json --samples 10 --view-cell 256
try "pvs tile larger than the field" "" -- pvs field.exr -o out/p.json --samples 10 --tile 1000
try "pvs view filter of 9 neighbours" "" -- pvs field.exr -o out/p.json --samples 10 --view-filter 9
try "pvs refraction beyond 1" "" -- pvs field.exr -o out/p.json --samples 10 --refraction 1.5
try "pvs resumed with another curvature" "" -- pvs field.exr -o out/p.json --samples 10 --seed 9 --curvature --resume prev_pvs.bin
try "pvs maximum distance below the least" "" -- pvs field.exr -o out/p.json --samples 10 --max-distance 0
try "pvs band with H1 below H0" "" -- pvs field.exr -o out/p.json --samples 10 --view-height 3,1
try "pvs mask of the wrong size" "" -- pvs field.exr -o out/p.json --samples 10 --view-mask mask_small.png
try "pvs budget of 0" "" -- pvs field.exr -o out/p.json --samples 0
try "pvs view cell in hexadecimal" "" -- pvs field.exr -o out/p.json --samples 10 --view-cell 0x10
try "pvs pixel error beyond reach" "" -- pvs field.exr -o out/p.json --pixel-error 1e-9
try "pvs estimate entries negative" "" -- pvs field.exr -o out/p.json --samples 10 --estimate-entries -1
try "pvs without a budget" "" -- pvs field.exr -o out/p.json
try "pvs output not JSON" "" -- pvs field.exr -o out/p.exr --samples 10
try "pvs bitset is the output" "" -- pvs field.exr -o out/p.json --samples 10 --bitset out/p.json
try "pvs preview of a view cell without a preview" "" -- pvs field.exr -o out/p.json --samples 10 --preview-view-cell 3,3
try "pvs preview of a view cell outside the field" "" -- pvs field.exr -o out/p.json --samples 10 --preview out/p.png --preview-view-cell 300,3
try "pvs resume without a seed" "" -- pvs field.exr -o out/p.json --samples 10 --resume prev_pvs.bin
try "pvs resume with the filter" "" -- pvs field.exr -o out/p.json --samples 10 --seed 2 --resume prev_pvs.bin --filter 1
try "pvs resume on another grid" "" -- pvs field.exr -o out/p.json --samples 10 --seed 2 --resume prev_pvs.bin --tile 8
try "pvs resume from a file not a bitset" "" -- pvs field.exr -o out/p.json --samples 10 --seed 2 --resume prev_pvs.json
try "pvs resume from another field's bitset" "" -- pvs field.exr -o out/p.json --samples 10 --seed 2 --z-scale 2 --resume prev_pvs.bin
try "pvs resume file as the output" "" -- pvs field.exr -o out/p.json --samples 10 --seed 2 --resume prev_pvs.bin --bitset prev_pvs.bin
try "sun position without a time" "" -- sunpos --lat 45 --lon 7
try "sun position at a time without a zone" "" -- sunpos --lat 45 --lon 7 --at 2026-06-21T12:00:00
try "sun position at a day that does not exist" "" -- sunpos --lat 45 --lon 7 --at 2026-02-30T12:00:00Z
try "sun position at a latitude beyond the pole" "" -- sunpos --lat 95 --lon 7 --at 2026-06-21T12:00:00Z
try "sun position beyond its years" "" -- sunpos --lat 45 --lon 7 --at 1700-06-21T12:00:00Z
# Environment.
try "HFVIS_LINE_LAYOUT not line or step" HFVIS_LINE_LAYOUT=diagonal -- svf field.exr -o out/o.exr
try "HFVIS_PROFILE not 0 or 1" HFVIS_PROFILE=yes -- svf field.exr -o out/o.exr
try "HFVIS_KERNEL_DIR without the kernels" HFVIS_KERNEL_DIR=/nonexistent -- svf field.exr -o out/o.exr
try "POCL_CACHE_DIR empty" POCL_CACHE_DIR= -- svf field.exr -o out/o.exr
try "POCL_CACHE_DIR a file" POCL_CACHE_DIR=field.tif -- devices
