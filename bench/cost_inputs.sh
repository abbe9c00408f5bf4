# bench/cost_inputs.sh: sourced by bench/cost_against.sh and bench/tree_peaks_cost_parts.sh (the
# whole-command timings against an older build): their inputs and their median.

# cost_input CONTENT SIZE BUILD_DIR DATA_DIR: prints the path of DATA_DIR/CONTENT_SIZE.exr, written
# first if missing: "city" by BUILD_DIR's hfvis_bench (the city DSM hard case), any other content
# by data/make_data.py (its synthetic fields: fractal, ...).
cost_input() {
  local content=$1 size=$2 build_dir=$3 data=$4
  local file=$data/${content}_$size.exr
  if [[ ! -f $file ]]; then
    if [[ $content == city ]]; then
      "$build_dir/bench/hfvis_bench" field city "$size" "$file" > /dev/null
    else
      /usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/../data/make_data.py" --size "$size" --out "$data" --no-dem \
        --fields "$content" > /dev/null
    fi
  fi
  echo "$file"
}

# The median of the numbers on standard input, one per line.
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
