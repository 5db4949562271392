#!/usr/bin/env bash
# The layering of the library (docs/architecture.md), checked on every #include of src/,
# include/flexkin/ and apps/: a file may include only headers of its own layer or of the layers
# it is allowed to depend on. Run by ctest as "layers"; prints each include that runs the wrong
# way and exits 1 if there is one.
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
cd "$root"

# The layer of each public header (include/flexkin/NAME.h).
declare -A header_layer=(
  [error]=chain [chain]=chain [vocabulary]=chain [curves]=chain [leader]=chain
  [colliders]=world
  [link_step]=sequential [propagate]=sequential [tree]=sequential [tree_overall]=overall [tree_scenario]=io
  [overall]=overall
  [run]=run [frames]=run [dynamics]=dynamics
  [arm]=arm [robot_tree]=arm [strands]=strands [groom]=groom [strand_file]=io
  [scenario]=io [result_io]=io [robot_scenario]=io [scenario_kind]=io [any_scenario]=scenario
  [flexkin]=umbrella
  [render]=render [strands_render]=render [viewer]=viewer [strands_viewer]=viewer [gltf]=gltf
  [urdf]=urdf [draw]=draw
)
# What each layer may include besides itself.
declare -A allowed=(
  [chain]=""
  [world]="chain"
  [sequential]="chain world"
  [overall]="chain world sequential"
  [run]="chain world sequential overall"
  [dynamics]="chain world sequential overall"
  [arm]="chain world sequential"
  [strands]="chain world sequential overall dynamics"
  [io]="chain world sequential overall run dynamics arm strands"
  [groom]="chain world sequential overall run arm io strands"
  [scenario]="chain world sequential overall run dynamics arm io strands groom"
  [umbrella]="chain world sequential overall run dynamics arm strands io groom scenario"
  [render]="chain world sequential overall run arm io strands groom"
  [viewer]="chain world sequential overall run arm io strands groom"
  [gltf]="chain world sequential overall run arm io render"
  [urdf]="chain world sequential overall run arm io"
  [draw]="chain world sequential overall run arm io strands groom render viewer gltf"
  [apps]="chain world sequential overall run dynamics arm io strands groom scenario render viewer gltf urdf draw"
)

layer_of_path() {  # a file of the tree -> its layer
  case "$1" in
    include/flexkin/*) local name; name=$(basename "$1" .h); echo "${header_layer[$name]:-unknown}" ;;
    src/*) echo "$1" | cut -d/ -f2 ;;
    apps/*) echo apps ;;
  esac
}

layer_of_include() {  # an include "x/y.h" -> its layer, or "" for a header of another kind
  case "$1" in
    flexkin/*) local name; name=$(basename "$1" .h); echo "${header_layer[$name]:-unknown}" ;;
    */*) local dir=${1%%/*}; [ -d "src/$dir" ] && echo "$dir" || echo "" ;;
    *) echo "" ;;
  esac
}

bad=0
checked=0
while IFS= read -r file; do
  from=$(layer_of_path "$file")
  [ -n "$from" ] || continue
  if [ "$from" = unknown ]; then
    echo "$file: a public header of no known layer (add it to tests/layers/check.sh)"; bad=1; continue
  fi
  while IFS= read -r inc; do
    to=$(layer_of_include "$inc")
    [ -n "$to" ] || continue
    checked=$((checked + 1))
    if [ "$to" = unknown ]; then
      echo "$file: includes \"$inc\", a public header of no known layer"; bad=1; continue
    fi
    [ "$to" = "$from" ] && continue
    case " ${allowed[$from]} " in
      *" $to "*) ;;
      *) echo "$file ($from) includes \"$inc\" ($to): $from may include only: ${allowed[$from]:-nothing else}"; bad=1 ;;
    esac
  done < <(sed -n 's/^#include "\([^"]*\)".*/\1/p' "$file")
done < <(find src include apps \( -name '*.h' -o -name '*.cc' \) | sort)
echo "layers: $checked includes checked"
[ "$checked" -gt 100 ] || { echo "layers: too few includes found; is this the source tree?"; exit 1; }
exit $bad
